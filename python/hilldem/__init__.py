"""hilldem: a discrete-element engine for unsaturated granular materials, from Python.

The engine is the C++ library the `hilldem` CLI runs (hilldem._core); this package adds the
scenario builder (hilldem.ScenarioBuilder); hilldem.lab holds the lab tests (gradings, genesis, the
triaxial test, the study). Units are SI throughout. docs/python.md is the manual.
"""
from ._core import (FIX_ALL, FIX_SPIN, FIX_SPIN_X, FIX_SPIN_Y, FIX_SPIN_Z, FIX_VELOCITY, FIX_X, FIX_Y, FIX_Z,
                    InputError, RunError, Simulation, bench_bed, lab, verify)
from .builder import ScenarioBuilder, toml_table
from .scenario import load_checkpoint, load_scenario, scenario_from_text

import sys as _sys

_sys.modules[__name__ + ".lab"] = lab  # `import hilldem.lab` and `from hilldem.lab import ...` work too

__all__ = ["Simulation", "ScenarioBuilder", "load_scenario", "scenario_from_text", "load_checkpoint", "verify", "bench_bed", "lab",
           "InputError", "RunError", "toml_table", "FIX_X", "FIX_Y", "FIX_Z", "FIX_SPIN_X", "FIX_SPIN_Y", "FIX_SPIN_Z",
           "FIX_VELOCITY", "FIX_SPIN", "FIX_ALL"]
