"""Regenerate the README's before / after pictures: cut planes of one benchmark block against
its true rings, the default evidence fit of an earlier checkout beside this one's.

    python docs/img/make_before_after.py NAME OLD_CHECKOUT

NAME is one of :data:`PICTURES`; OLD_CHECKOUT a git worktree of the commit it was drawn
against, e.g. ``git worktree add /tmp/v21 08ecf04``. Each checkout scores the block in a
process of its own, so the two woodcam packages never meet.
"""

import pickle
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: picture -> (seed, block, faces, the commit the README's picture was drawn against, what it shows)
PICTURES = {
    "knot_end_7777.png": (7777, 20, "three", "08ecf04",
                          "FIT_VERSION 21: a ray that would leave by a photographed face showing no knot was not "
                          "drawn; 22: it stops before that face"),
    "outward_stem_9101.png": (9101, 5, "full", "7f7a4a3",
                              "FIT_VERSION 22: the knots' bend was left out where the stem's pith lay beyond the side "
                              "where the rings count the most years; 23: the bend starts from a stem whose growth "
                              "time rises away from its pith"),
    "knot_corner_9101.png": (9101, 14, "full", "cdee99e",
                             "FIT_VERSION 24: a knot seen at one block corner ran on through the block and out by "
                             "a face that shows no knot; 25: it ends before that face"),
    "knot_pairs_9101.png": (9101, 5, "full", "d8b12bc",
                            "FIT_VERSION 25: two knots' ends paired nearest first, crossed; 26: paired as their "
                            "masks and rings say"),
}

_SCORE = """
import pickle, sys, warnings
sys.path.insert(0, {code!r})
warnings.simplefilter("ignore")
from woodcam.bench_realistic import score_block
from woodcam.inference.fit import FIT_VERSION
r = score_block({seed}, {index}, ("evidence",), "noisy", {faces!r}, "realistic", keep_lines=True)
sys.stdout.buffer.write(pickle.dumps((FIT_VERSION, r["evidence"]["matched_2"], r["planes"]["evidence"])))
"""


def _planes(code: Path, seed: int, index: int, faces: str):
    out = subprocess.run([sys.executable, "-c", _SCORE.format(code=str(code), seed=seed, index=index, faces=faces)],
                         capture_output=True, check=True).stdout
    return pickle.loads(out)


def before_after(old: str, seed: int, index: int, faces: str, out: Path) -> None:
    """Draw ``out``: block ``(seed, index)`` of the realistic generator, noisy ``faces``
    ("full" or "three"), fitted by the checkout at ``old`` and by this one."""
    sys.path.insert(0, str(ROOT))
    from woodcam.inference.evaluate import plot_planes

    planes = {}
    for code in (Path(old), ROOT):
        version, share, lines = _planes(code, seed, index, faces)
        planes[f"FIT_VERSION {version} ({share:.1f} % within 2 mm)"] = lines
    plot_planes(out, planes, title=f"seed {seed} block {index}, {faces} noisy faces: true rings black")


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in PICTURES:
        sys.exit("usage: python docs/img/make_before_after.py NAME OLD_CHECKOUT; NAME one of "
                 + ", ".join(f"{k} (drawn against {v[3]})" for k, v in PICTURES.items()))
    seed, index, faces, _, _ = PICTURES[sys.argv[1]]
    before_after(sys.argv[2], seed, index, faces, Path(__file__).parent / sys.argv[1])
