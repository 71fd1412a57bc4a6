// WorkSplit: which balls each thread of the force pass takes, cut at equal work.
//
// Why: rows and contacts per ball vary across a specimen (denser at the bottom of a bed, none above
// its surface), so ranges of equal numbers of balls leave one thread waiting at the end of every
// pass. The ranges are cut at equal work instead, and the work is shared in proportion to the
// threads' measured speeds (the cores of a shared machine run at different speeds). Which balls a
// thread sums changes no result (Simulation's force sum has one order for any split), so the split
// is a matter of speed only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hilldem {

class WorkSplit {
 public:
  // Before a force pass run by `threads` threads over `balls` balls and `rows` rows: split again
  // when the balls, rows or thread count changed, every kSplitEvery passes, or when the threads'
  // speeds moved their shares (measured every kSpeedEvery passes). Ball i's work counts its
  // ball-ball rows row_first[i + 1] − row_first[i] that the pass visits and its wall rows
  // wall_first[i + 1] − wall_first[i]. `given`: shares of the work per thread that replace the
  // measured ones (Simulation::thread_shares; used when it has one per thread). Returns whether
  // the ranges were cut anew.
  bool prepare(std::size_t threads, std::size_t balls, std::size_t rows, const std::vector<double>& given,
               const std::uint32_t* row_first, const std::uint32_t* wall_first);
  // Thread t's range of balls [begin(t), end(t)).
  std::size_t begin(std::size_t t) const { return start_[t]; }
  std::size_t end(std::size_t t) const { return start_[t + 1]; }
  // Each thread's share of the work (normalised); the law of motion splits its balls alike.
  const std::vector<double>& shares() const { return share_; }
  // Thread t spent `seconds` [s] in its blocks in this pass (its speed: work over time).
  void add_busy(std::size_t t, double seconds) { busy_[t] += seconds; }

 private:
  // start_[t]: the first ball of thread t's range, cut at equal work.
  void split(std::size_t threads, std::size_t balls, const std::vector<double>& given, const std::uint32_t* row_first,
             const std::uint32_t* wall_first);
  bool balance_speeds(std::size_t balls, const std::vector<double>& given);  // true: the shares moved

  static constexpr int kSplitEvery = 50;
  static constexpr int kSpeedEvery = 10;
  std::vector<std::size_t> start_;      // threads' ranges of balls
  std::vector<std::uint64_t> prefix_;   // running sum of the work per ball
  std::size_t rows_ = 0;                // rows when the split was made
  int split_age_ = 0;                   // force passes since
  std::vector<double> share_;           // threads' shares of the work
  std::vector<double> busy_;            // threads' time in the blocks since the speeds were measured [s]
  int speed_age_ = 0;                   // force passes since the speeds were measured afresh
};

}  // namespace hilldem
