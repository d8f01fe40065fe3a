"""Regenerate docs/img/knot_end_7777.png: cut planes of dev seed 7777 block 20 (three noisy
faces) against the true rings, the default evidence fit of an earlier checkout beside this
one's. The picture in the README was drawn against a git worktree of 08ecf04 (FIT_VERSION 21:
a ray that would leave by a photographed face showing no knot was not drawn) and FIT_VERSION
22 (it stops before that face).

    git worktree add /tmp/v21 08ecf04
    python docs/img/make_knot_end.py /tmp/v21
"""

import pickle
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OUT = Path(__file__).parent / "knot_end_7777.png"
SEED, INDEX, FACES = 7777, 20, "three"

# each checkout scores the block in a process of its own, so the two woodcam packages never meet
_SCORE = """
import pickle, sys, warnings
sys.path.insert(0, {code!r})
warnings.simplefilter("ignore")
from woodcam.bench_realistic import score_block
from woodcam.inference.fit import FIT_VERSION
r = score_block({seed}, {index}, ("evidence",), "noisy", {faces!r}, "realistic", keep_lines=True)
sys.stdout.buffer.write(pickle.dumps((FIT_VERSION, r["evidence"]["matched_2"], r["planes"]["evidence"])))
"""


def _planes(code: Path):
    out = subprocess.run([sys.executable, "-c", _SCORE.format(code=str(code), seed=SEED, index=INDEX, faces=FACES)],
                         capture_output=True, check=True).stdout
    return pickle.loads(out)


def main(old: str):
    sys.path.insert(0, str(ROOT))
    from woodcam.inference.evaluate import plot_planes

    planes = {}
    for code in (Path(old), ROOT):
        version, share, lines = _planes(code)
        planes[f"FIT_VERSION {version} ({share:.1f} % within 2 mm)"] = lines
    plot_planes(OUT, planes, title=f"seed {SEED} block {INDEX}, {FACES} noisy faces: true rings black")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python docs/img/make_knot_end.py OLD_CHECKOUT (e.g. a git worktree of 08ecf04)")
    main(sys.argv[1])
