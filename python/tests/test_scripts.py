"""scripts/write_results.py writes a results table from JSON that may hold null (a count or error
the run did not know): such a cell is "-", never a made-up 0."""

import json
import subprocess
import sys

from conftest import source_file


def test_write_results_shows_unknown_values_as_a_dash(tmp_path):
    result = {"run": "S2", "config": "semsegmap", "n_localizations": 3, "n_error_below_1m": None,
              "n_wrong": 0, "mean_translation_error_m": None, "mean_rotation_error_deg": None,
              "recall_along_trajectory": 0.5}
    results = tmp_path / "localization.json"
    results.write_text(json.dumps({"results": [result]}))
    doc = tmp_path / "results.md"
    doc.write_text("before\n<!-- results:t -->\nold\n<!-- /results:t -->\nafter\n")
    subprocess.run([sys.executable, source_file("scripts/write_results.py"), "t",
                    f"front camera={results}", "--doc", str(doc)], check=True)
    row = [line for line in doc.read_text().splitlines() if line.startswith("| front camera |")]
    assert row == ["| front camera | S2 | semsegmap | 3 | - | 0 | - | 0.50 |"], doc.read_text()
