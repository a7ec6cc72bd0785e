"""Shared fixtures of the Python suite. ctest runs each file with PYTHONPATH=<build>/python,
SEMSEGMAP_BINARY (the command line, to compare with) and SEMSEGMAP_BUILD_DIR set."""

import os
import shutil
import subprocess

import pytest

import semsegmap as ssm

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHARED_DATA = os.path.join(os.path.dirname(SOURCE_DIR), "shared", "data")
TINY_S1 = "sim:world=1,run=S1,preset=tiny"
TINY_S2 = "sim:world=1,run=S2,preset=tiny"

needs_sim = pytest.mark.skipif(
    not ssm.WITH_SIM, reason="this build has no simulator (SEMSEGMAP_WITH_SIM=OFF)")
needs_torch = pytest.mark.skipif(
    not ssm.WITH_TORCH,
    reason="this build has no learned descriptors (SEMSEGMAP_WITH_TORCH=OFF)")
needs_pcl = pytest.mark.skipif(
    not ssm.WITH_PCL, reason="this build has no FPFH descriptor (SEMSEGMAP_WITH_PCL=OFF)")


def source_file(relative):
    return os.path.join(SOURCE_DIR, relative)


@pytest.fixture(scope="session")
def binary():
    """The built command line: SEMSEGMAP_BINARY, else build/semsegmap of this checkout."""
    path = os.environ.get("SEMSEGMAP_BINARY") or source_file("build/semsegmap")
    if not os.access(path, os.X_OK):
        pytest.skip(f"no semsegmap binary at {path} (set SEMSEGMAP_BINARY)")
    return path


def start_cli(binary, *args, cwd=None):
    """Starts the command line, to run beside Python's own work."""
    return subprocess.Popen([binary, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=cwd)


def finish_cli(process):
    """Its stdout once it ends (a failure shows its stderr)."""
    out, err = process.communicate()
    assert process.returncode == 0, f"{' '.join(process.args)} failed:\n{err}"
    return out


def run_cli(binary, *args, cwd=None):
    """Runs the command line; its stdout."""
    return finish_cli(start_cli(binary, *args, cwd=cwd))


@pytest.fixture(scope="session")
def config():
    """The shipped SemSegMap configuration (its describer needs libtorch)."""
    return ssm.load_config(ssm.shipped_file("config/semsegmap.yaml"))


def one_line(message):
    """The library's errors are one line."""
    text = str(message)
    assert "\n" not in text, text
    return text


@pytest.fixture
def tmp_dir(tmp_path):
    yield str(tmp_path)
    shutil.rmtree(tmp_path, ignore_errors=True)
