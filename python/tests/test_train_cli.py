"""`semsegmap train` stopped early keeps what it has: the best model so far and the history."""

import csv
import os
import signal
import subprocess

from conftest import TINY_S1, needs_sim, needs_torch


@needs_sim
@needs_torch
def test_a_training_stopped_after_its_first_epoch_keeps_its_history_and_model(tmp_dir, binary):
    history = os.path.join(tmp_dir, "history.csv")
    model = os.path.join(tmp_dir, "net.model")
    train = subprocess.Popen(
        [binary, "train", "--descriptor", "semsegmap-net", "--dataset", TINY_S1,
         "--max-frames", "30", "--epochs", "1000", "--anchors-per-epoch", "64", "--threads", "1",
         "--history", history, "--out", model],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        for line in train.stdout:  # the epoch's line comes after its history row is written
            if line.startswith("epoch 1 "):
                break
        else:
            raise AssertionError(f"train ended before its first epoch (exit {train.wait()})")
    finally:
        train.send_signal(signal.SIGKILL)
        train.wait()
    with open(history, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) >= 1 and rows[0]["epoch"] == "1" and rows[0]["best"] == "1", rows
    assert float(rows[0]["loss"]) > 0
    assert os.path.getsize(model) > 0  # the first epoch is the best so far, saved as it came
