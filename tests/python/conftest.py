"""Shared fixtures of the Python tests. CTest (tests/python/tests.cmake) sets PYTHONPATH to the build
tree's module, HILLDEM_CLI to the CLI built with it and HILLDEM_SOURCE_DIR to the repository."""
import os
import pathlib
import subprocess

import pytest


def _env(name):
    v = os.environ.get(name)
    if not v:
        pytest.exit(f"{name} is not set: run these tests through CTest (tests/python/tests.cmake)", returncode=2)
    return v


@pytest.fixture(scope="session")
def source_dir():
    """The repository [path]."""
    return pathlib.Path(_env("HILLDEM_SOURCE_DIR"))


@pytest.fixture(scope="session")
def cli():
    """Run the hilldem CLI with the given arguments; returns the CompletedProcess (check=True)."""
    exe = _env("HILLDEM_CLI")

    def run(*args, check=True):
        return subprocess.run([exe, *map(str, args)], capture_output=True, text=True, check=check)

    return run


@pytest.fixture()
def assembly(source_dir):
    """The memo's 27-grain assembly under gravity (examples/assembly_27.toml), built fresh."""
    import hilldem
    return hilldem.load_scenario(source_dir / "examples" / "assembly_27.toml")
