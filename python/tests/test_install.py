"""cmake --install into a fresh prefix: the package imports from the prefix's site-packages, away
from the build and source trees, and finds the installed configs and models."""

import glob
import os
import subprocess
import sys

import pytest

SCRIPT = """
import os, sys
import semsegmap as ssm
assert ssm.__file__.startswith(sys.argv[1]), ssm.__file__
assert ssm.data_dir() == os.path.join(sys.argv[1], "share", "semsegmap"), ssm.data_dir()
config = ssm.load_config(ssm.shipped_file("config/semsegmap.yaml"))
assert os.path.isfile(config.descriptor.model), config.descriptor.model
assert config.descriptor.model.startswith(sys.argv[1])
d = ssm.make_describer(ssm.DescriptorConfig(kind="eigen"))
print("installed ok", ssm.__version__, d.dimension)
"""


def test_the_installed_package_imports_from_the_prefix(tmp_dir):
    build = os.environ.get("SEMSEGMAP_BUILD_DIR")
    if not build:
        pytest.skip("SEMSEGMAP_BUILD_DIR is not set (ctest sets it)")
    prefix = os.path.join(tmp_dir, "prefix")
    done = subprocess.run(["cmake", "--install", build, "--prefix", prefix], capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    modules = glob.glob(os.path.join(prefix, "lib", "python*", "*-packages", "semsegmap",
                                     "_semsegmap*.so"))
    assert len(modules) == 1, f"no module installed under {prefix}/lib/python*/"
    site = os.path.dirname(os.path.dirname(modules[0]))
    for f in ("__init__.py", "__init__.pyi", "_semsegmap.pyi", "py.typed", "_paths.py"):
        assert os.path.isfile(os.path.join(site, "semsegmap", f)), f
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = site
    done = subprocess.run([sys.executable, "-c", SCRIPT, prefix], capture_output=True, text=True,
                          cwd=tmp_dir, env=env)
    assert done.returncode == 0, done.stderr
    assert "installed ok" in done.stdout
