#include "hilldem/parallel/partition.hpp"

#include <algorithm>
#include <stdexcept>
#include <zoltan.h>

namespace hilldem::parallel {

namespace {
// What Zoltan's query functions read during RcbPartition::cut.
struct Points {
  const std::vector<Vec3>* x;
  const std::vector<double>* w;
};

int num_obj(void* data, int* ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<int>(static_cast<Points*>(data)->x->size());
}

void obj_list(void* data, int, int, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int wdim, float* w, int* ierr) {
  const Points& p = *static_cast<Points*>(data);
  for (std::size_t i = 0; i < p.x->size(); ++i) {
    gids[i] = static_cast<ZOLTAN_ID_TYPE>(i);  // (only the cuts are kept: ids need be unique per rank only)
    lids[i] = static_cast<ZOLTAN_ID_TYPE>(i);
    if (wdim > 0) w[i] = static_cast<float>((*p.w)[i]);
  }
  *ierr = ZOLTAN_OK;
}

int num_geom(void*, int* ierr) {
  *ierr = ZOLTAN_OK;
  return 3;
}

void geom_multi(void* data, int, int, int n, ZOLTAN_ID_PTR, ZOLTAN_ID_PTR lids, int, double* xyz, int* ierr) {
  const Points& p = *static_cast<Points*>(data);
  for (int k = 0; k < n; ++k) {
    const Vec3& x = (*p.x)[lids[k]];
    xyz[3 * k] = x.x;
    xyz[3 * k + 1] = x.y;
    xyz[3 * k + 2] = x.z;
  }
  *ierr = ZOLTAN_OK;
}

void check(int status, const char* what) {
  if (status != ZOLTAN_OK && status != ZOLTAN_WARN) throw std::runtime_error(std::string("Zoltan: ") + what + " failed");
}
}  // namespace

RcbPartition::RcbPartition(MPI_Comm comm) {
  MPI_Comm_size(comm, &size_);
  zz_ = Zoltan_Create(comm);
  if (zz_ == nullptr) throw std::runtime_error("Zoltan_Create failed");
  Zoltan_Set_Param(zz_, "DEBUG_LEVEL", "0");
  Zoltan_Set_Param(zz_, "LB_METHOD", "RCB");
  Zoltan_Set_Param(zz_, "NUM_GID_ENTRIES", "1");
  Zoltan_Set_Param(zz_, "NUM_LID_ENTRIES", "1");
  Zoltan_Set_Param(zz_, "OBJ_WEIGHT_DIM", "1");
  Zoltan_Set_Param(zz_, "RETURN_LISTS", "NONE");  // only the cuts: the balls move by Domain's own exchange
  Zoltan_Set_Param(zz_, "KEEP_CUTS", "1");         // owner() and near() ask the cuts
  Zoltan_Set_Param(zz_, "RCB_REUSE", "0");
}

RcbPartition::~RcbPartition() { Zoltan_Destroy(&zz_); }

void RcbPartition::cut(const std::vector<Vec3>& points, const std::vector<double>& weights) {
  Points p{&points, &weights};
  Zoltan_Set_Num_Obj_Fn(zz_, num_obj, &p);
  Zoltan_Set_Obj_List_Fn(zz_, obj_list, &p);
  Zoltan_Set_Num_Geom_Fn(zz_, num_geom, &p);
  Zoltan_Set_Geom_Multi_Fn(zz_, geom_multi, &p);
  int changes = 0, gid_entries = 0, lid_entries = 0, n_import = 0, n_export = 0;
  ZOLTAN_ID_PTR import_g = nullptr, import_l = nullptr, export_g = nullptr, export_l = nullptr;
  int *import_p = nullptr, *import_to = nullptr, *export_p = nullptr, *export_to = nullptr;
  check(Zoltan_LB_Partition(zz_, &changes, &gid_entries, &lid_entries, &n_import, &import_g, &import_l, &import_p,
                            &import_to, &n_export, &export_g, &export_l, &export_p, &export_to),
        "Zoltan_LB_Partition");
  Zoltan_LB_Free_Part(&import_g, &import_l, &import_p, &import_to);
  Zoltan_LB_Free_Part(&export_g, &export_l, &export_p, &export_to);
}

int RcbPartition::owner(const Vec3& x) const {
  if (size_ == 1) return 0;
  double c[3] = {x.x, x.y, x.z};
  int proc = -1, part = -1;
  check(Zoltan_LB_Point_PP_Assign(zz_, c, &proc, &part), "Zoltan_LB_Point_PP_Assign");
  return proc;
}

void RcbPartition::near(const Vec3& x, double distance, const PeriodicBox& box, int self, std::vector<int>& out) const {
  if (size_ == 1) return;
  const std::size_t first = out.size();
  // The box about x, and its periodic images that reach into the periodic box from the other side.
  const Vec3 l = box.length();
  int lo_shift[3], hi_shift[3];
  for (int d = 0; d < 3; ++d) {
    lo_shift[d] = box.periodic[d] && x[d] + distance > box.hi[d] ? -1 : 0;
    hi_shift[d] = box.periodic[d] && x[d] - distance < box.lo[d] ? 1 : 0;
  }
  std::vector<int> procs(static_cast<std::size_t>(size_)), parts(static_cast<std::size_t>(size_));
  for (int sx = lo_shift[0]; sx <= hi_shift[0]; ++sx)
    for (int sy = lo_shift[1]; sy <= hi_shift[1]; ++sy)
      for (int sz = lo_shift[2]; sz <= hi_shift[2]; ++sz) {
        const Vec3 c{x.x + sx * l.x, x.y + sy * l.y, x.z + sz * l.z};
        int n_procs = 0, n_parts = 0;
        check(Zoltan_LB_Box_PP_Assign(zz_, c.x - distance, c.y - distance, c.z - distance, c.x + distance,
                                      c.y + distance, c.z + distance, procs.data(), &n_procs, parts.data(), &n_parts),
              "Zoltan_LB_Box_PP_Assign");
        for (int k = 0; k < n_procs; ++k)
          if (procs[k] != self) out.push_back(procs[k]);
      }
  std::sort(out.begin() + static_cast<long>(first), out.end());
  out.erase(std::unique(out.begin() + static_cast<long>(first), out.end()), out.end());
}

}  // namespace hilldem::parallel
