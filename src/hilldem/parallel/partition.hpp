// RcbPartition: the sub-domains of the ranks, by Zoltan's recursive coordinate bisection (RCB).
//
// Why Zoltan: a well-kept partitioner (Sandia, Debian's libtrilinos-zoltan-dev) whose RCB cuts are
// kept on every rank, so that any rank can say, from a position alone, which rank owns it
// (owner) and which ranks' sub-domains come within a distance of it (near): ownership and ghosts
// need no messages. The outermost sub-domains extend to infinity.
#pragma once

#include <vector>

#include <mpi.h>

#include "hilldem/contact/cell_grid.hpp"
#include "hilldem/core/vec3.hpp"

struct Zoltan_Struct;

namespace hilldem::parallel {

class RcbPartition {
 public:
  explicit RcbPartition(MPI_Comm comm);
  ~RcbPartition();
  RcbPartition(const RcbPartition&) = delete;
  RcbPartition& operator=(const RcbPartition&) = delete;

  // New cuts from this rank's points [m] (positions in the box) and their weights (collective).
  void cut(const std::vector<Vec3>& points, const std::vector<double>& weights);
  // The rank whose sub-domain holds x [m] (x inside the box along periodic directions).
  int owner(const Vec3& x) const;
  // Every rank other than `self` whose sub-domain comes within `distance` [m] of x along each axis,
  // across the periodic boundaries of `box` too, sorted, appended to `out`.
  void near(const Vec3& x, double distance, const PeriodicBox& box, int self, std::vector<int>& out) const;

 private:
  Zoltan_Struct* zz_ = nullptr;
  int size_ = 1;
};

}  // namespace hilldem::parallel
