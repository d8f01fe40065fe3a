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


def test_a_stage_bar_names_the_running_stage_and_ends_at_its_total():
    from woodcam._progress import StageBar

    out = _Terminal()
    with StageBar(["rough", "finish"], desc="cutting", file=out, delay=0) as bar:
        for name in bar.stages:
            with bar.stage(name):
                pass
    text = out.getvalue()
    assert "cutting: rough" in text and "cutting: finish" in text and "2/2" in text


def test_a_stage_bar_is_drawn_in_the_middle_of_a_long_stage():
    """tqdm draws a delayed bar only at its next step: a stage bar whose first stage lasted a
    minute stayed blank for that minute; its timer draws it once the delay is past."""
    from woodcam._progress import StageBar

    out = _Terminal()
    with StageBar(["fit", "bake"], desc="bake", file=out, delay=0.05) as bar:
        with bar.stage("fit"):
            deadline = time.monotonic() + 5
            while "0/2" not in out.getvalue() and time.monotonic() < deadline:
                time.sleep(0.01)
            assert "bake: fit" in out.getvalue() and "0/2" in out.getvalue()
        with bar.stage("bake"):
            pass


def test_no_stage_bar_in_a_log_file():
    from woodcam._progress import StageBar

    log = io.StringIO()
    with StageBar(["a"], desc="x", file=log, delay=0) as bar, bar.stage("a"):
        pass
    assert log.getvalue() == ""


def test_no_bar_redraws_itself_before_the_delay():
    """tqdm's set_postfix/set_description redraw at once, delay or not: the appearance nets'
    bars were drawn for trainings of under a second, stuck at "0/48" (the count of a bar being
    iterated is synced only at its own redraws)."""
    eager = [f"{p.relative_to(PACKAGE)}:{i}" for p in PACKAGE.rglob("*.py") if p.name != "_progress.py"
             for i, line in enumerate(p.read_text().splitlines(), 1)
             if re.search(r"\.set_(postfix|description)(_str)?\(", line) and "refresh=False" not in line]
    assert eager == []
