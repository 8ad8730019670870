"""Shared by the g2s Python tests: the g2s CLI (to compare with), the real scans, and a small
cloud made by `g2s synth`."""
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def cli():
    """The g2s command of the same build (ctest sets G2S_CLI), else build/g2s."""
    return os.environ.get("G2S_CLI") or str(REPO / "build" / "g2s")


def data_dir():
    return pathlib.Path(os.environ.get("G2S_DATA_DIR") or os.environ.get("G2S_DEFAULT_DATA_DIR")
                        or REPO.parent / "shared" / "data")


def run_cli(*args):
    """Runs g2s with args; returns (exit code, stdout, stderr)."""
    done = subprocess.run([cli(), *map(str, args)], capture_output=True, text=True, check=False)
    return done.returncode, done.stdout, done.stderr


@pytest.fixture(scope="session")
def torus_ply(tmp_path_factory):
    path = tmp_path_factory.mktemp("clouds") / "torus.ply"
    code, _, err = run_cli("synth", "torus", "--points", "20000", "-o", path)
    assert code == 0, err
    return path
