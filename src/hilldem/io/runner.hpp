// Runner: executes a scenario's stages on its Simulation, writes the CSV history and collects probes;
// also the run's outputs and fault tolerance:
//   * snapshots for ParaView ([snapshots], io/vtk_writer.hpp),
//   * checkpoints ([checkpoints], io/checkpoint.hpp) from which resume_scenario continues a run
//     bitwise as if it had never stopped: the runner saves its position inside the current stage
//     (steps done, the motion imposed so far, saved fixities), the probes so far, the servos and how
//     far the history and snapshot index had got,
//   * progress on stderr (io/progress.hpp),
//   * blow-up detection: a non-finite state or a free ball moving more than blowup_fraction × its
//     radius in one step stops the run (RunError) with the step, the ball, its contacts and a
//     checkpoint of the state to inspect.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "hilldem/io/checkpoint.hpp"
#include "hilldem/io/progress.hpp"
#include "hilldem/io/scenario.hpp"

namespace hilldem {

struct ProbeValue {
  std::string label;
  std::string quantity;  // "contact.normal_force"
  std::string target;    // "balls 1-2"
  std::string unit;
  double value = 0.0;
};

// A run decomposed over MPI ranks (parallel/run_mpi.hpp, docs/mpi.md): every rank runs the same
// stages on its part of the run (its Simulation's balls are its own and its ghosts), and whatever
// the runner reads of the whole run, or must decide as one, it gets here. Rank 0 writes every file
// (histories, probes, snapshots, checkpoints: from the gathered whole run) and every line. Every call
// is collective (every rank makes it, in the same order), except rank(), size() and owns().
class RunDecomposition {
 public:
  virtual ~RunDecomposition() = default;
  // Make sim, the whole run (the same on every rank), this rank's part. reach [m]: the largest
  // distance between two balls' surfaces a stage asks for (make_wet's gap), so the ghosts cover it.
  virtual void attach(Simulation& sim, double reach) = 0;
  // Let go of the attached Simulation (its domain set to null; it keeps this rank's part), so that
  // another one can be attached (the lab tests attach one specimen after another; attach detaches
  // the previous one first). Call it before the attached Simulation ends. Nothing when none is attached.
  virtual void detach() = 0;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Whether this rank owns local ball i (after attach).
  virtual bool owns(std::size_t local) const = 0;
  // The local index of the whole run's ball `global` (a stage's selection is of the whole run's
  // indices) where this rank holds it, owned or as a ghost; -1 where it does not (after attach).
  virtual std::int64_t local_of(std::size_t global) const = 0;
  // The whole run on rank 0 (with its cycle state when with_cycle: checkpoints); empty elsewhere.
  virtual Simulation gather(bool with_cycle) = 0;
  // Rank 0's value on every rank.
  virtual std::int64_t from_root(std::int64_t v) = 0;
  virtual double from_root(double v) = 0;
  virtual std::string from_root(const std::string& s) = 0;
  // The largest over the ranks, and the sum (integers: exact in any order).
  virtual std::int64_t max(std::int64_t v) = 0;
  virtual std::uint64_t sum(std::uint64_t v) = 0;
};

struct RunOptions {
  bool quiet = false;             // no stage lines, listings or progress
  std::string output_dir;         // overrides the scenario's [output] dir when not empty
  bool write_files = true;        // false: never write any file (verify, tests)
  ProgressMode progress = ProgressMode::Auto;  // Auto: in place on a terminal, plain lines otherwise
  double progress_interval = 10.0;             // [s] between plain progress lines
  std::ostream* progress_stream = nullptr;     // default std::cerr
  // Tests: stop right after this step as if the process had died there (no stage-end outputs, no
  // final checkpoint); RunResult::halted says it happened. -1: never.
  std::int64_t halt_after_step = -1;
  // Asked after every cycle whether to stop there (the Python module's run_stages answers Ctrl-C
  // with it): when it returns true the run ends at that cycle boundary as at halt_after_step
  // (RunResult::halted; no stage-end outputs). Empty: never asked.
  std::function<bool()> stop_requested;
  // The run over MPI ranks this process is one rank of (null: the whole run here).
  RunDecomposition* decomposition = nullptr;
};

struct RunResult {
  std::vector<ProbeValue> probes;
  std::string history_path;     // "" when none was written
  std::string snapshot_dir;     // "" when no snapshots were written
  std::string checkpoint_dir;   // "" when no checkpoints were written
  std::string last_checkpoint;  // the newest checkpoint file written ("" when none)
  bool halted = false;          // RunOptions::halt_after_step was reached
  int stopped_by = 0;           // the signal that stopped the run between cycles (io/stop_signal.hpp); 0: none
  bool already_complete = false;  // resume_scenario found a finished run
  std::string resumed_from;       // resume_scenario: the checkpoint it continued from
  const ProbeValue* find(const std::string& label) const;
};

// Output settings given on the command line (hilldem run --snapshots-every N ...), applied over the
// scenario's [snapshots], [checkpoints] and blowup_fraction by run_scenario. The CLI fills them while
// parsing; nothing else should. The settings a run used are saved in its checkpoints, so
// resume_scenario continues with them.
struct OutputOverrides {
  std::optional<std::int64_t> snapshot_every;     // turns snapshots on; 0: at stage ends only
  std::optional<bool> snapshot_binary;
  std::optional<std::int64_t> checkpoint_every;   // [steps]
  std::optional<double> checkpoint_seconds;       // [s]
  bool no_checkpoints = false;
  std::optional<double> blowup_fraction;
  void apply(Scenario& sc) const;
};
OutputOverrides& output_overrides();

// Runs every stage in order. After SIGINT, SIGTERM or SIGHUP (when io/stop_signal's handlers are
// installed) it finishes the cycle, writes a checkpoint and returns with RunResult::stopped_by set. Stage lines and listings go to `log`. Throws RunError when a stage
// fails, InputError when an output cannot be created.
RunResult run_scenario(Scenario& sc, const RunOptions& options, std::ostream& log);

// The checkpoint to resume from: `path` itself when it is a file; for a folder (an output folder or
// its checkpoints/ folder) the newest checkpoint that reads back intact, older ones when the newest
// is damaged (each skipped file is reported on `log`). InputError when there is none.
std::string find_checkpoint(const std::string& path, std::ostream& log);

// Continue the run saved in a checkpoint (file or folder, as find_checkpoint). The scenario is
// rebuilt into `sc` from the text the checkpoint carries; outputs continue in the checkpoint's output
// folder (the parent of its checkpoints/ folder) unless options.output_dir is given. A corrupt,
// truncated or mismatched checkpoint is an InputError naming the problem.
RunResult resume_scenario(const std::string& path, Scenario& sc, const RunOptions& options, std::ostream& log);
// The same from a checkpoint already read (outputs go to options.output_dir; none when it is empty).
RunResult resume_scenario(const CheckpointReader& checkpoint, Scenario& sc, const RunOptions& options, std::ostream& log);

// Value of a history or probe quantity: an engine quantity (io/quantity.hpp), or a servo.* quantity
// of servo `servo` (>= 0).
double evaluate(const Scenario& sc, const Quantity& q, int servo);

// One line per contact: pieces, model, rule and why, state. The "contacts" CLI command and the
// list_contacts stage print it.
std::string contact_listing(const Simulation& sim);

// The probe table `hilldem run` prints.
std::string probe_table(const RunResult& result);

// What a checkpoint holds, in words (hilldem inspect): its kind, clock, stage position, counts and
// sections; with `ball`, that ball's state and every contact it has.
std::string describe_checkpoint(const std::string& path, std::optional<std::int64_t> ball);
std::string describe_checkpoint(const CheckpointReader& checkpoint, std::optional<std::int64_t> ball);

}  // namespace hilldem
