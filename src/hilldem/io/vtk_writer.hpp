// Snapshots for ParaView: VTK XML PolyData files (.vtp) and time-series index files (.pvd).
//
// Each snapshot k writes up to three files into the snapshot folder:
//   balls_<k>.vtp     one point (vertex) per ball at its centre. Point data: id, radius [m], mass [kg],
//                     velocity [m/s], spin [rad/s], contact_force [N], contact_moment [N m],
//                     fixity (bit mask), groups (bit mask), group (lowest group
//                     index, -1 none), coordination (active contacts), wet_contacts, moisture_force [N]
//                     (Σ|F^m| of its contacts). Field data: TimeValue [s], step, group_names.
//   contacts_<k>.vtp  one line per contact, from ball 1's centre to ball 2's centre (or to the contact
//                     point on a wall). Cell data: ball1, ball2 (-1 for a wall), wall (-1 for a ball),
//                     kind (0 ball-ball, 1 ball-wall), model (0 linear, 1 hill), mois_state (0 dry,
//                     1 ruptured, 2 wet), wet (0/1), active (0/1), gap [m], normal (unit), normal_force
//                     [N] (compression > 0), moisture_force [N] (≤ 0), shear_force [N] (vector),
//                     shear_force_mag [N], force [N] (total on piece 2), contact_point [m], suction [Pa].
//   walls_<k>.vtp     triangles: each facet; a square patch of each plane around the balls; cylinders
//                     as 48-sided tubes over their extent (or the balls' span when infinite). Cell data:
//                     wall (index), force [N] (the wall's total), normal_force [N], velocity [m/s].
//                     Field data: wall_names.
// and rewrites balls.pvd, contacts.pvd and walls.pvd (atomically) to list every snapshot with its
// simulated time, so ParaView opens each as a time series.
//
// Data are written in VTK's "appended raw" binary encoding (little-endian, UInt64 headers), or as
// ASCII for inspection.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hilldem/engine/simulation.hpp"

namespace hilldem {

struct SnapshotOptions {
  bool contacts = true;  // write contacts_<k>.vtp
  bool walls = true;     // write walls_<k>.vtp
  bool binary = true;    // appended raw binary; false: ASCII
};

struct SnapshotEntry {
  std::int64_t index = 0;  // k in the file names
  std::int64_t step = 0;
  double time = 0.0;       // [s]
};

// One snapshot's files (k formatted as 6 digits).
void write_balls_vtp(const Simulation& sim, const std::string& path, bool binary);
void write_contacts_vtp(const Simulation& sim, const std::string& path, bool binary);
void write_walls_vtp(const Simulation& sim, const std::string& path, bool binary);

class SnapshotSeries {
 public:
  SnapshotSeries(std::string folder, SnapshotOptions options);
  // Write the current state as the next snapshot; with replace_same_step, a snapshot already taken at
  // this step is overwritten instead (stage ends that did not cycle). Throws RunError on I/O failure.
  void write(const Simulation& sim, bool replace_same_step = false);
  const std::vector<SnapshotEntry>& entries() const { return entries_; }
  // Continue a series after a restart: keep these entries (later files are overwritten as they are
  // written again) and rewrite the index files.
  void restore(std::vector<SnapshotEntry> entries);
  const std::string& folder() const { return folder_; }

 private:
  void write_index() const;
  std::string folder_;
  SnapshotOptions options_;
  std::vector<SnapshotEntry> entries_;
};

}  // namespace hilldem
