"""Cut planes of one benchmark block against its true rings, the default evidence fit of an
earlier checkout beside this one's (the README's before / after pictures).

Each checkout scores the block in a process of its own, so the two woodcam packages never meet.
"""

import pickle
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

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
