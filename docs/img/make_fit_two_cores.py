"""Figure for the README ("One fit on both cores"): wall seconds of the default evidence fit
(six noisy faces, residual on) of seed 44021's blocks 0-23 on one core and on two.

The records are JSON lines written by runs of ``woodcam.bench_realistic.score_block(44021, i,
("evidence",), "noisy", "full", residual=True)`` with ``WOODCAM_WORKERS`` 1 and 2, one block
at a time on an otherwise idle machine: ``{"i", "w" (workers), "kind", "wall"}`` per fit.

    python docs/img/make_fit_two_cores.py ONE_AND_TWO.jsonl [...] FINAL_TWO.jsonl OUT.png
"""

from __future__ import annotations

import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(argv: list[str]) -> None:
    *both, final, out = argv
    runs: dict = {}
    for path in both:
        for line in open(path):
            r = json.loads(line)
            runs.setdefault(r["i"], {})[r["w"]] = r
    last = {r["i"]: r for r in map(json.loads, open(final))}
    idx = sorted(runs, key=lambda i: -runs[i]["1"]["wall"])
    x = np.arange(len(idx))
    fig, ax = plt.subplots(figsize=(10, 3.6), dpi=110)
    ax.bar(x - 0.27, [runs[i]["1"]["wall"] for i in idx], 0.27, label="one core (WOODCAM_WORKERS=1)", color="#b0b0b0")
    ax.bar(x, [runs[i]["2"]["wall"] for i in idx], 0.27, label="two cores, f60daa4", color="#4a86c5")
    ax.bar(x + 0.27, [last[i]["wall"] for i in idx], 0.27, label="two cores, held-out folds shared from both ends",
           color="#1f4e79")
    finish(fig, ax, [f"{i}{'*' if runs[i]['1']['kind'] == 'knotted' else ''}" for i in idx],
           "seed 44021 block (* knotted), slowest one-core fit first",
           "Evidence fit, six noisy faces, residual on: one core against two (the same fits bit for bit)", out)


def finish(fig, ax, labels: list[str], xlabel: str, title: str, out: str, **tick_kw) -> None:
    """The fit-time figures' common end: the 10 s goal line, block labels under the bars,
    axis labels, title and legend; saved to ``out``."""
    ax.axhline(10, color="#c0392b", lw=1, ls="--")
    ax.text(len(labels) - 0.5, 10.2, "goal 10 s", color="#c0392b", ha="right", fontsize=8)
    ax.set_xticks(np.arange(len(labels)), labels, **{"fontsize": 8, **tick_kw})
    ax.set_xlabel(xlabel)
    ax.set_ylabel("wall s of fit_block")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, frameon=False)
    fig.tight_layout()
    fig.savefig(out)

if __name__ == "__main__":
    main(sys.argv[1:])
