"""Regenerate docs/img/knot_end_7777.png: cut planes of dev seed 7777 block 20 (three noisy
faces) against the true rings, the default evidence fit of an earlier checkout beside this
one's. The picture in the README was drawn against a git worktree of 08ecf04 (FIT_VERSION 21:
a ray that would leave by a photographed face showing no knot was not drawn) and FIT_VERSION
22 (it stops before that face).

    git worktree add /tmp/v21 08ecf04
    python docs/img/make_knot_end.py /tmp/v21
"""

import sys
from pathlib import Path

from _before_after import before_after

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python docs/img/make_knot_end.py OLD_CHECKOUT (e.g. a git worktree of 08ecf04)")
    before_after(sys.argv[1], 7777, 20, "three", Path(__file__).parent / "knot_end_7777.png")
