// The engine's state in checkpoint sections, and its canonical bytes for bitwise comparisons.
//
// Sections written by write_simulation (all version 1):
//   sim.clock     time, steps, last_dt
//   sim.settings  every SimulationSettings field
//   sim.groups    group names, in bit order
//   sim.table     the contact-model assignment table
//   sim.balls     every BallStore column (BallStore::for_each_column: none can be forgotten)
//   sim.walls     every Wall field, imposed motion and force sums included
//   sim.contacts  every ContactStore column (ContactStore::zip_columns), neighbour rows included
//   sim.info      neighbour-list rebuilds and unassigned pairs (informational)
//
// read_simulation rebuilds a Simulation from them so that cycling on gives bitwise the same
// results as the run that wrote them (tests/restart checks it). The engine keeps its neighbour
// list and "forces are up to date" flag private, so the restore detects contacts once
// (Simulation::update_forces) and then puts back every saved contact row, ball and wall sum: the
// existing contacts, their order and every force are those saved; only which non-contact
// neighbour pairs are listed may differ, and no result depends on that. (Periodic runs: positions
// are re-wrapped into the box one neighbour-list rebuild earlier than in the original run, which can
// change the last bits.)
#pragma once

#include <cstdint>
#include <string>

#include "hilldem/control/servo.hpp"
#include "hilldem/engine/simulation.hpp"
#include "hilldem/io/checkpoint.hpp"

namespace hilldem {

void write_simulation(CheckpointWriter& w, const Simulation& sim);

// Replace `sim` with the state in r's sim.* sections. Every index, enum and count is validated
// (InputError naming the section). With prepare_to_cycle, the contact detection and force sums are
// made ready so that the next cycle continues exactly; without it (inspection of a blown-up state)
// nothing is recomputed.
void read_simulation(const CheckpointReader& r, Simulation& sim, bool prepare_to_cycle = true);

// A servo's state (control/servo.hpp): its settings and whether it is on; the speed it last imposed is
// written for inspection (the servo recomputes it at the start of every cycle). For drivers that keep
// servos of their own: one call per servo, in a section of theirs.
void write_servo(SectionWriter& w, const Servo& servo);
void read_servo(SectionReader& r, Servo& servo);  // validates the ranges (InputError)

// Canonical bytes of the physical state: clock, settings, every ball column, every wall, and every
// contact that exists (all columns; neighbour-only rows are bookkeeping and left out). Equal bytes
// = bitwise-equal states.
std::string state_bytes(const Simulation& sim);
// 64-bit FNV-1a of state_bytes, as 16 hex digits.
std::string state_digest(const Simulation& sim);
// Rough memory of a state [bytes]: its ball and contact columns, doubled for the engine's own
// per-ball records and row lists and for the growth of vectors. For out-of-memory messages.
double state_memory_estimate(std::size_t balls, std::size_t rows);
// Where two states first differ, in words ("" when they are bitwise equal).
std::string state_difference(const Simulation& a, const Simulation& b);

}  // namespace hilldem
