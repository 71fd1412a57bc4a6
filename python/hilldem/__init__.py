"""hilldem: a discrete-element engine for unsaturated granular materials, from Python.

The engine is the C++ library the `hilldem` CLI runs (hilldem._core); this package adds the
scenario builder (hilldem.ScenarioBuilder); hilldem.lab holds the lab tests (gradings, genesis, the
triaxial test, the study). Units are SI throughout. docs/python.md is the manual.
"""
import os as _os

# OpenMP's idle threads spin 30,000 times before they sleep, not libgomp's 300,000: on cores that other
# processes hold, the long spin made two threads many times slower than one (docs/performance.md,
# "Threads on busy cores"; the CLI sets the same). libgomp reads it when it is loaded, that is, by the
# import below, unless another module loaded it first. A user's own setting stands.
if "GOMP_SPINCOUNT" not in _os.environ and "OMP_WAIT_POLICY" not in _os.environ:
    _os.environ["GOMP_SPINCOUNT"] = "30000"

from ._core import (FIX_ALL, FIX_SPIN, FIX_SPIN_X, FIX_SPIN_Y, FIX_SPIN_Z, FIX_VELOCITY, FIX_X, FIX_Y, FIX_Z,
                    InputError, RunError, Simulation, bench_bed, lab, verify)
from .builder import ScenarioBuilder, toml_table
from .scenario import load_checkpoint, load_scenario, scenario_from_text

import sys as _sys

_sys.modules[__name__ + ".lab"] = lab  # `import hilldem.lab` and `from hilldem.lab import ...` work too

__all__ = ["Simulation", "ScenarioBuilder", "load_scenario", "scenario_from_text", "load_checkpoint", "verify", "bench_bed", "lab",
           "InputError", "RunError", "toml_table", "FIX_X", "FIX_Y", "FIX_Z", "FIX_SPIN_X", "FIX_SPIN_Y", "FIX_SPIN_Z",
           "FIX_VELOCITY", "FIX_SPIN", "FIX_ALL"]
