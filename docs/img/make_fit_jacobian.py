"""Figure for the README ("The radial search's exact Jacobian, FIT_VERSION 14"): wall seconds of
the default evidence fit (six noisy faces, residual on) of the knotted blocks of fresh seeds
60661 and 35089, FIT_VERSION 13 and 14 run alternately in groups on an otherwise idle machine.

The records are JSON lines ``{"tag": "old" | "new", "seed", "i", "wall", "chosen"}``, one per
fit (``fit_block(block, "evidence", residual=True)`` after a warm-up fit in each process).

    python docs/img/make_fit_jacobian.py TIMES.jsonl OUT.png
"""

from __future__ import annotations

import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from make_fit_two_cores import finish  # noqa: E402  (run from docs/img: its folder is on the path)


def main(argv: list[str]) -> None:
    path, out = argv
    runs: dict = {}
    for r in map(json.loads, open(path)):
        runs.setdefault((r["seed"], r["i"]), {})[r["tag"]] = r
    keys = sorted((k for k in runs if len(runs[k]) == 2), key=lambda k: -runs[k]["old"]["wall"])
    x = np.arange(len(keys))
    fig, ax = plt.subplots(figsize=(10, 3.6), dpi=110)
    ax.bar(x - 0.2, [runs[k]["old"]["wall"] for k in keys], 0.4, label="FIT_VERSION 13 (forward differences)",
           color="#b0b0b0")
    ax.bar(x + 0.2, [runs[k]["new"]["wall"] for k in keys], 0.4,
           label="FIT_VERSION 14 (exact Jacobian; residual folds, stem and cone starts on both cores)", color="#1f4e79")
    finish(fig, ax, [f"{s % 1000}/{i}" for s, i in keys],
           "knotted block (seed 60661 as 661/i, 35089 as 89/i), slowest FIT_VERSION 13 fit first",
           "Evidence fit of knotted blocks, six noisy faces, residual on, two cores: the same choices", out,
           fontsize=7, rotation=60)

if __name__ == "__main__":
    main(sys.argv[1:])
