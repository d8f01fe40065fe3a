"""Progress bars (woodcam._progress): drawn on a terminal for work that lasts, never into a log."""

from __future__ import annotations

import io
import re
import time
from pathlib import Path

from woodcam._progress import progress_bar

PACKAGE = Path(__file__).resolve().parents[1] / "woodcam"


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_bar_is_drawn_on_a_terminal_once_the_work_lasts():
    out = _Terminal()
    for _ in progress_bar(range(5), desc="cutting", unit="pass", file=out, delay=0):
        pass
    assert "cutting" in out.getvalue() and "5/5" in out.getvalue()


def test_no_bar_in_a_log_file_or_pipe():
    # tqdm's redraws piled up on one line of a log and its last state was printed twice
    log = io.StringIO()
    for _ in progress_bar(range(5), desc="cutting", unit="pass", file=log, delay=0):
        time.sleep(0.01)
    bar = progress_bar(total=3, desc="cutting", unit="pass", file=log, delay=0)
    bar.update(3)
    bar.close()
    assert log.getvalue() == ""


def test_no_bar_for_work_shorter_than_the_delay_or_when_not_enabled():
    out = _Terminal()
    for _ in progress_bar(range(5), desc="cutting", unit="pass", file=out):  # the default 2 s delay
        pass
    for _ in progress_bar(range(5), desc="cutting", unit="pass", file=out, delay=0, enabled=False):
        pass
    assert out.getvalue() == ""


def test_every_bar_of_the_package_goes_through_the_helper():
    direct = [str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
              if p.name != "_progress.py" and re.search(r"^\s*(from tqdm|import tqdm)", p.read_text(), re.M)]
    assert direct == []
