"""Simulations from TOML scenarios and checkpoints (the same reader and checks as the CLI)."""
import os

from ._core import Simulation


def load_scenario(path):
    """The simulation a TOML scenario file describes (docs/scenario-format.md), with its stages.

    Bad input raises hilldem.InputError (a ValueError) naming the file, the key and the allowed range,
    as `hilldem check` prints it."""
    return Simulation._from_file(os.fspath(path))


def scenario_from_text(text, name="<text>"):
    """The simulation TOML scenario text describes; `name` stands for the file in error messages."""
    return Simulation._from_text(text, name)


def load_checkpoint(path):
    """The engine state of a checkpoint file (written by Simulation.save_checkpoint or by the CLI's
    runs), ready to cycle on: cycling continues bitwise as the run that wrote it would have. Only the
    engine state (sections sim.*) is read: a CLI run's stages, servos and histories are not."""
    return Simulation._from_checkpoint(os.fspath(path))
