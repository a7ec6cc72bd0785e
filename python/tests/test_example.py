"""The example of examples/ runs as it is documented (with fewer frames)."""

import os
import re
import subprocess
import sys

from conftest import needs_sim, needs_torch, source_file


@needs_sim
@needs_torch  # the shipped config's describer is learned
def test_map_and_localize_example(tmp_dir):
    out = os.path.join(tmp_dir, "s1.map")
    done = subprocess.run(
        [sys.executable, source_file("examples/map_and_localize.py"), "--frames", "40", "--out",
         out], capture_output=True, text=True, cwd=tmp_dir)
    assert done.returncode == 0, done.stderr
    text = done.stdout
    assert re.search(r"^map: \d+ segments from 40 frames", text, re.M), text
    m = re.search(r"^localized (\d+) of 40 frames, (\d+) within 1 m", text, re.M)
    assert m and int(m.group(1)) > 10, text
    assert "T_map_base =" in text and os.path.getsize(out) > 0
