#include "hilldem/engine/work_split.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace hilldem {

bool WorkSplit::prepare(std::size_t threads, std::size_t balls, std::size_t rows, const std::vector<double>& given,
                        const std::uint32_t* row_first, const std::uint32_t* wall_first) {
  // The split is a serial pass over the balls and moves slowly with the contacts: it is redone only
  // when needed (see the header).
  bool resplit = start_.size() != threads + 1 || start_.back() != balls || rows_ != rows || share_.size() != threads ||
                 ++split_age_ >= kSplitEvery;
  if (!resplit && ++speed_age_ >= kSpeedEvery) resplit = balance_speeds(balls, given);
  if (resplit) {
    split(threads, balls, given, row_first, wall_first);
    rows_ = rows;
    split_age_ = 0;
  }
  if (resplit || speed_age_ >= kSpeedEvery) {  // the speeds measured afresh
    busy_.assign(threads, 0.0);
    speed_age_ = 0;
  }
  return resplit;
}

bool WorkSplit::balance_speeds(std::size_t balls, const std::vector<double>& given) {
  // Each thread's speed over the passes since the split: its work (split's units) over its time in
  // the blocks [s]. Shares of the work in proportion to the speeds, half way from the last shares
  // (the speeds are noisy); a new split only if a share moved by more than 1 %.
  const std::size_t threads = share_.size();
  if (!given.empty() || threads < 2 || busy_.size() != threads || start_.size() != threads + 1 ||
      prefix_.size() != balls + 1)
    return false;
  std::vector<double> speed(threads);
  double total = 0.0;
  for (std::size_t t = 0; t < threads; ++t) {
    const double work = static_cast<double>(prefix_[start_[t + 1]] - prefix_[start_[t]]);
    if (!(busy_[t] > 0.0) || !(work > 0.0)) return false;
    speed[t] = work / busy_[t];
    total += speed[t];
  }
  // (No share below a tenth of an equal one: a thread with no balls could not be timed again.)
  const double least = 0.1 / static_cast<double>(threads);
  std::vector<double> share(threads);
  double sum = 0.0;
  for (std::size_t t = 0; t < threads; ++t) {
    share[t] = std::max(0.5 * share_[t] + 0.5 * speed[t] / total, least);
    sum += share[t];
  }
  bool moved = false;
  for (std::size_t t = 0; t < threads; ++t) {
    moved |= std::abs(share[t] / sum - share_[t]) > 0.01;
    share_[t] = share[t] / sum;
  }
  return moved;
}

void WorkSplit::split(std::size_t threads, std::size_t balls, const std::vector<double>& given,
                      const std::uint32_t* row_first, const std::uint32_t* wall_first) {
  // Work of ball i in the pass, in units of a neighbour row that is not a contact: two for the ball
  // itself (its record, its half of the force sum), four for each row the pass visits (gather, law
  // and scatter) and four for each of its wall rows, which its thread runs.
  const std::size_t n = balls;
  start_.assign(threads + 1, n);
  start_[0] = 0;
  if (threads <= 1 || n == 0) {
    // (Equal shares: without them every pass would ask for a new split.)
    const std::size_t count = std::max<std::size_t>(threads, 1);
    share_.assign(count, 1.0 / static_cast<double>(count));
    return;
  }
  std::vector<std::uint64_t>& prefix = prefix_;
  prefix.resize(n + 1);
  prefix[0] = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t rows = row_first[i + 1] - row_first[i];
    prefix[i + 1] = prefix[i] + 2 + 4 * rows + 4 * (wall_first[i + 1] - wall_first[i]);
  }
  // Thread t's share of the work: given, or in proportion to the threads' speeds (equal at first).
  const std::size_t count = threads;
  const double equal = 1.0 / static_cast<double>(count);
  if (given.size() == count) {
    const double sum = std::accumulate(given.begin(), given.end(), 0.0);
    share_.resize(count);
    for (std::size_t t = 0; t < count; ++t) share_[t] = sum > 0.0 ? std::max(given[t], 0.0) / sum : equal;
  } else if (share_.size() != count) {
    share_.assign(count, equal);
  }
  double before = 0.0;
  for (std::size_t t = 1; t < count; ++t) {
    before += share_[t - 1];
    const auto target = static_cast<std::uint64_t>(static_cast<double>(prefix[n]) * std::min(before, 1.0));
    start_[t] = static_cast<std::size_t>(std::lower_bound(prefix.begin(), prefix.end(), target) - prefix.begin());
  }
}

}  // namespace hilldem
