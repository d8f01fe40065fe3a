"""Regenerate docs/img/outward_stem_9101.png: cut planes of dev seed 9101 block 5 (six noisy
faces) against the true rings, the default evidence fit of an earlier checkout beside this
one's. The picture in the README was drawn against a git worktree of 7f7a4a3 (FIT_VERSION 22:
the knots' bend was left out where the stem's pith lay beyond the side where the rings count
the most years) and FIT_VERSION 23 (the bend starts from a stem whose growth time rises away
from its pith).

    git worktree add /tmp/v22 7f7a4a3
    python docs/img/make_outward_stem.py /tmp/v22
"""

import sys
from pathlib import Path

from _before_after import before_after

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python docs/img/make_outward_stem.py OLD_CHECKOUT (e.g. a git worktree of 7f7a4a3)")
    before_after(sys.argv[1], 9101, 5, "full", Path(__file__).parent / "outward_stem_9101.png")
