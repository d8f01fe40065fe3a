"""G-code reader: RS274/NGC text -> a :class:`Program` of straight moves in millimetres.

Data form
---------
A :class:`Program` holds ``n`` straight moves as arrays: ``start_mm, end_mm : (n, 3) float`` in
the G-code frame (the G54 work frame as the machine has it before the program runs, the frame of
``start_mm``; the machine's own origin, ``G53``, lies at ``machine_zero_mm`` in it),
millimetres, whatever ``G20/G21`` the program used; ``kind : (n,) uint8`` (0 = rapid ``G0``, 1 =
feed ``G1/G2/G3``), ``tool : (n,) int`` (the tool number loaded by the last ``M6``, 0 before
any), ``line : (n,) int`` (1-based source line) and ``feed_mm_min, spindle_rpm : (n,) float``
(``spindle_rpm`` is 0 while the spindle is off), ``inch : (n,) bool`` (the move was programmed
in ``G20``, inches: the lengths as the program wrote them; all ``False`` for a program built
from arrays), ``ran_line : (n,) int`` (the main-program line the move ran under: ``line``, or
for a subroutine's move the line of the outermost call that ran it; ``until_line`` counts by
it). Arcs are split into chords whose sagitta is at
most ``chord_tol_mm`` (default :data:`woodcam.tolerances.ARC_CHORD_TOL_MM`), so every arc vertex
lies exactly on the analytic circle (helix). ``warnings`` lists ``"line N: ..."`` strings;
``messages`` the operator messages the program says as it runs, ``"line N: ..."`` too (its
``(MSG,...)`` and ``(DEBUG,...)`` comments, the parameters' values put in, as LinuxCNC shows
them); ``printed`` its ``(PRINT,...)`` texts, in the same form: LinuxCNC writes those to the
terminal it was started from, never to the operator's screen (``interpreter="linuxcnc"``
too: the texts it writes to its standard output, each with the line it ran).

The language (parameters, expressions, O-word subroutines and loops, work offsets, canned
cycles, dialects) is :mod:`woodcam.toolpath.interpreter`; ``interpreter="linuxcnc"`` runs
LinuxCNC's own interpreter instead (:mod:`woodcam.toolpath.linuxcnc`).

Start position: the machine starts at ``start_mm`` (default :data:`DEFAULT_START_MM`, 10 mm
over the work zero); the G28/G30 home positions are stored there too. A cut before the program
has set all three axes is warned about.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import overload
from pathlib import Path

import numpy as np

from .._checks import as_floats, check_number, check_vector
from .._repr import summary_repr
from .._types import ArrayLike, PathLike
from ..errors import WoodcamError
from ..tolerances import ARC_CHORD_TOL_MM
from ..units import say_length
from .interpreter import ARC, MM_PER_INCH, GcodeError, Interpreter, nul_byte_error, source_lines

__all__ = ["DEFAULT_START_MM", "FEED", "MAX_CHORDS_PER_ARC", "MM_PER_INCH", "RAPID", "GcodeError",
           "Move", "Program", "gcode_text", "program_from_canonical", "read_gcode"]

RAPID, FEED = 0, 1
_KIND_NAMES = ("rapid", "feed")

#: Where the machine starts (G-code frame, mm): over the work zero at a clearance height.
DEFAULT_START_MM = (0.0, 0.0, 10.0)
#: Chords one arc may become before woodcam refuses it (an arc of radius 1e9 mm would need
#: millions): a 1 m radius half circle at 0.005 mm needs ~1,100.
MAX_CHORDS_PER_ARC = 200_000


@dataclass(frozen=True)
class Move:
    """One straight move. ``start_mm, end_mm : (3,)`` G-code (G54) frame, mm."""

    start_mm: tuple[float, float, float]
    end_mm: tuple[float, float, float]
    kind: str  # "rapid" | "feed"
    tool: int
    line: int
    feed_mm_min: float
    spindle_rpm: float


@dataclass
class Program:
    """Straight moves of a G-code program as arrays (see the module docstring for the form).

    ``n`` moves: ``start_mm, end_mm (n, 3)`` float, G-code (G54 work) frame, mm whatever
    G20/G21 the program used; ``kind (n,)`` (0 rapid, 1 feed), ``tool (n,)``, ``line (n,)``
    (1-based source line), ``feed_mm_min (n,)`` mm/min, ``spindle_rpm (n,)``; ``inch (n,)``
    bool and ``ran_line (n,)`` int per move as commented below.

    ``source``: where the program came from (the file name, ``"<string>"`` for text);
    ``tool_numbers``: the distinct tool numbers its moves use, sorted; ``warnings``,
    ``messages`` (its ``(MSG,...)`` / ``(DEBUG,...)`` operator messages) and ``printed`` (its
    ``(PRINT,...)`` texts): lists of ``"line N: ..."`` strings (module docstring).
    """

    __repr__ = summary_repr  # arrays as shapes: a notebook shows one line

    start_mm: np.ndarray
    end_mm: np.ndarray
    kind: np.ndarray
    tool: np.ndarray
    line: np.ndarray
    feed_mm_min: np.ndarray
    spindle_rpm: np.ndarray
    source: str = "<string>"
    tool_numbers: list[int] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    messages: list[str] = field(default_factory=list)
    printed: list[str] = field(default_factory=list)
    #: per move: programmed in G20 (inches); None (the default) is all False (mm, G21)
    inch: np.ndarray = None  # type: ignore[assignment]
    #: per move: the main-program line it ran under (a subroutine's moves: the line of the
    #: outermost call that ran them, M98 too; :meth:`until_line`); None (the default) is ``line``
    ran_line: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.inch is None:
            self.inch = np.zeros(len(self.kind), bool)
        if self.ran_line is None:
            self.ran_line = np.array(self.line, int)

    def __len__(self) -> int:
        return len(self.kind)

    @overload
    def __getitem__(self, i: int) -> Move: ...

    @overload
    def __getitem__(self, i: slice) -> Program: ...

    def __getitem__(self, i):
        """``program[i]``: move ``i`` as a :class:`Move`; ``program[a:b]``: those moves as a
        :class:`Program` (a list's slice: ``program[:10]`` is the first ten moves)."""
        if isinstance(i, slice):
            return self._subset(i)
        if isinstance(i, bool) or not isinstance(i, numbers.Integral):
            raise WoodcamError(f"Program: a move index must be an integer or a slice; got {i!r:.60}; "
                               "e.g. program[0] (a Move) or program[0:10] (a Program of ten moves)")
        return Move(tuple(map(float, self.start_mm[i])), tuple(map(float, self.end_mm[i])),
                    _KIND_NAMES[int(self.kind[i])], int(self.tool[i]), int(self.line[i]),
                    float(self.feed_mm_min[i]), float(self.spindle_rpm[i]))

    def _subset(self, k) -> Program:
        """The moves ``k`` (a slice or a boolean mask) as a program of the same source."""
        return Program(self.start_mm[k], self.end_mm[k], self.kind[k], self.tool[k],
                       self.line[k], self.feed_mm_min[k], self.spindle_rpm[k], self.source,
                       sorted(set(self.tool[k].tolist())), list(self.warnings),
                       list(self.messages), list(self.printed), self.inch[k], self.ran_line[k])

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    @property
    def moves(self) -> list[Move]:
        return list(self)

    def machining_time_s(self, rapid_mm_min: float = 5000.0) -> dict[int, tuple[float, float]]:
        """Estimated time per tool: ``{tool: (feed seconds, rapid seconds)}`` from the move
        lengths (mm), the programmed feeds (mm/min) and ``rapid_mm_min`` for rapids (the
        machine's rapid rate; no acceleration is modelled, so real jobs take longer). Tool 0's
        rapids before the first ``M6`` count to the tool they stand for
        (:meth:`tool_of_leading_rapids`, the tool simulate moves them with): a post's safe-Z
        move before the tool change was a 'T0' with seconds of rapids of its own."""
        rapid_mm_min = check_number(rapid_mm_min, "machining_time_s: rapid_mm_min", lo=0, lo_open=True,
                                    fix="the machine's rapid rate in mm/min, e.g. 5000")
        length = np.linalg.norm(self.end_mm - self.start_mm, axis=1)
        feed = self.kind == FEED
        tool = self.tool
        lead = self.tool_of_leading_rapids()
        if lead is not None:
            tool = np.where(tool == 0, lead, tool)
        with np.errstate(divide="ignore"):
            t = np.where(feed, 60.0 * length / np.maximum(self.feed_mm_min, 1e-9),
                         60.0 * length / rapid_mm_min)
        return {int(k): (float(t[feed & (tool == k)].sum()),
                         float(t[~feed & (tool == k)].sum()))
                for k in np.unique(tool)}

    def tool_of_leading_rapids(self) -> int | None:
        """The tool that tool 0's moves stand for: the first tool the program loads (``M6``)
        when tool 0 only makes rapids before it (a safe-Z move, Carbide Create's
        ``G53 G0 Z-5``, a ``G28``), which need no tool of their own; ``None`` when tool 0 also
        feeds or the program loads no tool."""
        loaded = self.tool[self.tool != 0]
        if not len(loaded) or (self.tool[self.kind == FEED] == 0).any():
            return None
        return int(loaded[0])

    def stepover_mm(self, spacing_mm: float = 0.1) -> float | None:
        """Typical distance (mm) between neighbouring passes of the feed moves: the median,
        over points every ``spacing_mm`` along the feeds, of the XY distance to the nearest
        point of another pass (not the same or the next source line, not stacked at the same
        XY, beside the point rather than ahead of it); ``None`` when under a tenth of the points
        have such a pass near them (a profile, a helix, crossing lines).
        Used to warn when the simulation grid is too coarse for the program (aliasing)."""
        from scipy.spatial import cKDTree

        f = self.kind == FEED
        a, b, ln = self.start_mm[f], self.end_mm[f], self.line[f]
        n = np.maximum(np.ceil(np.linalg.norm(b - a, axis=1) / spacing_mm).astype(int), 1)
        if n.sum() > 2_000_000:  # bounded cost on huge programs: coarser sampling
            return self.stepover_mm(spacing_mm * math.sqrt(n.sum() / 2_000_000))
        seg = np.repeat(np.arange(len(a)), n)
        t = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n) + 0.5) / n[seg]
        pts = a[seg] + t[:, None] * (b[seg] - a[seg])
        # One point per half-spacing XY cell: passes stacked at the same XY (depth levels,
        # repeated sweeps) otherwise fill the nearest neighbours with copies of the point
        # itself, and the pass beside it is never among them (a 2.4 mm step-over pocket in six
        # levels read as 0.05 mm)
        if len(pts) < 4:
            return None
        cell = np.floor(pts[:, :2] / (0.5 * spacing_mm)).astype(np.int64)
        cell -= cell.min(axis=0)
        first = np.sort(np.unique(cell[:, 0] * (int(cell[:, 1].max()) + 1) + cell[:, 1],
                                  return_index=True)[1])
        seg, pts = seg[first], pts[first]
        lines = ln[seg]
        if len(pts) < 4:
            return None
        k = min(48, len(pts))
        # The median over 4,000 query points (fixed seed) is as good as over all of them
        # (20,000 gave the same step-over on the corpus at 5x the cost).
        # Distances are lateral: across the query's XY direction (plunges have none and are
        # left out), so passes stacked at the same XY (depth levels) do not count.
        xy = pts[:, :2]
        dxy = (b - a)[:, :2]
        lxy = np.linalg.norm(dxy, axis=1)
        has_dir = np.flatnonzero(lxy[seg] > 1e-9)
        if not len(has_dir):
            return None
        q = np.random.default_rng(0).choice(has_dir, min(len(has_dir), 4_000), replace=False)
        u = dxy[seg[q]] / lxy[seg[q]][:, None]
        dist, idx = cKDTree(xy).query(xy[q], k=k)
        rel = xy[np.minimum(idx, len(xy) - 1)] - xy[q][:, None, :]
        lateral = np.abs(rel[..., 0] * u[:, None, 1] - rel[..., 1] * u[:, None, 0])
        along = np.abs(rel[..., 0] * u[:, None, 0] + rel[..., 1] * u[:, None, 1])
        # beside, not ahead: the next turn of a helix or a line crossing the pass is no
        # neighbouring pass (their points ahead read as 0.1-0.15 mm step-overs)
        near = np.minimum(idx, len(xy) - 1)
        # and running alongside (within 30 degrees): near where a line crosses the pass at a
        # slant (a raster's return diagonal to the next depth level) some of its points are
        # beside the query at any small distance (a 3 mm pocket in six levels read 0.75 mm)
        n_seg = seg[near]
        parallel = np.abs((dxy[n_seg] * u[:, None, :]).sum(axis=2)) \
            >= math.cos(math.radians(30)) * lxy[n_seg]
        other = (np.abs(lines[near] - lines[q][:, None]) > 1) & np.isfinite(dist) & \
            (lateral > 0.5 * spacing_mm) & (along <= lateral) & parallel
        d = np.where(other, lateral, np.inf).min(axis=1)
        d = d[np.isfinite(d)]
        # a pass beside under a tenth of the points: crossings, lead-ins, not a step-over
        return float(np.median(d)) if len(d) >= 0.1 * len(q) else None

    def until_line(self, line: int) -> Program:
        """The moves the program made up to and including main-program line ``line`` (the
        simulation scrubbed to that line): those of ``ran_line <= line``, so a subroutine call
        on a line ``<= line`` brings all its moves (nested calls too) and one after it none,
        wherever the subroutine's body lies; a line inside a body counts as a main-program line
        that runs no move."""
        return self.lines_between(None, line)

    def lines_between(self, after: int | None, until: int) -> Program:
        """The moves that ran under main-program lines ``after < ran_line <= until``
        (``after=None``: from the start; :meth:`until_line`): the next stretch when a
        simulation is scrubbed forward."""
        k = self.ran_line <= int(until)
        if after is not None:
            k &= self.ran_line > int(after)
        return self._subset(k)

    @classmethod
    def from_arrays(cls, start_mm, end_mm, *, kind=FEED, tool=1, line=0, feed_mm_min=1000.0,
                    spindle_rpm=18000.0, source="<arrays>") -> "Program":
        """Build a program directly from ``start_mm, end_mm : (n, 3)`` (tests, generators)."""
        s = np.asarray(start_mm, float).reshape(-1, 3)
        e = np.asarray(end_mm, float).reshape(-1, 3)
        n = len(s)
        full = lambda v, dt: np.broadcast_to(np.asarray(v, dt), (n,)).copy()  # noqa: E731
        t = full(tool, int)
        return cls(s, e, full(kind, np.uint8), t, full(line, int), full(feed_mm_min, float),
                   full(spindle_rpm, float), source, sorted(set(t.tolist())))


def _names_a_file(text: str) -> bool:
    """Is the one-line ``text`` the path of an existing file (a program saved without a G-code
    suffix, e.g. ``part.out``)? False for text no path can be (too long, a NUL)."""
    try:
        return len(text) < 4096 and Path(text).is_file()
    except (OSError, ValueError):
        return False


def gcode_text(path: PathLike) -> str:
    """The text of the G-code file ``path`` as :func:`read_gcode` reads it: the line ends as
    written (``newline=""``: numbered as LinuxCNC numbers them, :func:`.interpreter.source_lines`),
    bytes that are no UTF-8 replaced. Read a file once with it and pass the text with
    ``source=`` to read it more than once as the same bytes. A file with a NUL byte that hides
    words (:func:`.interpreter.nul_byte_error`) is no G-code text (an image, a program, a CAM
    project, a file saved as UTF-16) or a damaged one, and is refused, naming the line (its
    first line showed as a wall of bytes in a 'bad character' or 'unclosed comment' error);
    NULs with only NULs and blanks after them on their lines (a card's zero padding after the
    program) are read as LinuxCNC reads them, as the end of their lines."""
    data = Path(path).read_bytes()
    if b"\x00" not in data:
        return data.decode(errors="replace")
    text = data.decode(errors="replace")
    utf16 = data[:2] in (b"\xff\xfe", b"\xfe\xff")
    err = None if utf16 else nul_byte_error(source_lines(text))
    if not utf16 and err is None:
        return text
    what = ("saved as UTF-16 (Windows' 'Unicode'); save it as UTF-8 or ASCII" if utf16 else
            "a binary file (an image, a program, a CAM project?), or G-code damaged by the "
            f"NUL on line {err.line if err else 1} (LinuxCNC would drop the words after it); "
            "pass the G-code file the CAM software's post-processor wrote (.nc, .ngc, .tap, "
            ".gcode)")
    raise WoodcamError(f"{str(path)!r} is not G-code text: it holds NUL bytes "
                       f"(it starts {data[:8]!r}): {what}")


def read_gcode(text_or_path: str | PathLike, *, chord_tol_mm: float = ARC_CHORD_TOL_MM,
               start_mm: ArrayLike | None = None, dialect: str = "linuxcnc",
               interpreter: str = "woodcam", machine_zero_mm: ArrayLike | None = None,
               tool_diameters_mm: Mapping[int, float] | None = None,
               source: str | None = None) -> Program:
    """Read G-code text or a file path into a :class:`Program` of straight moves (G-code
    frame, mm).

    Parameters
    ----------
    text_or_path : str | os.PathLike
        Program text, or the path of a G-code file: a ``Path``, a one-line ``str`` naming an
        existing file, or one ending in ``.nc/.gcode/.ngc/.tap/.cnc/.txt`` (which must exist).
        Any other ``str`` is taken as program text.
    chord_tol_mm : float
        Largest sagitta (mm) between an arc and its chords.
    start_mm : (3,) float | None
        Start position in the G-code (G54) frame (mm); ``None``: :data:`DEFAULT_START_MM`.
    dialect : "linuxcnc" | "grbl" | "fanuc"
        Which controller's meaning the program has (:mod:`woodcam.toolpath.interpreter`).
    interpreter : "woodcam" | "linuxcnc"
        ``"linuxcnc"`` runs LinuxCNC's own interpreter (needs Debian's ``linuxcnc-uspace``).
    machine_zero_mm : (3,) float | None
        Where the machine's origin (``G53``) lies in the G-code (G54) frame of ``start_mm``, mm:
        LinuxCNC's G54 offset negated. ``None``: not known; a ``G53`` Z move is then taken as a
        retract to the start height and a warning names those lines
        (:mod:`woodcam.toolpath.interpreter`). ``(0, 0, 0)`` is LinuxCNC with every offset zero.
    tool_diameters_mm : {int: float} | None
        The cutters' diameters (mm) by tool number, as the user's tool table gives them: what
        a ``(DEBUG,...)``/``(PRINT,...)`` shows for ``#5410`` (the loaded tool's diameter in
        the machine's tool table). Without the loaded tool there, it says what LinuxCNC would
        show, with a warning; before the first ``M6`` (no tool loaded: LinuxCNC's T0 is no
        tool) it shows 0, as LinuxCNC. ``interpreter="linuxcnc"`` runs LinuxCNC with these
        diameters in its tool table and shows and warns the same.
    source : str | None
        The file ``text_or_path`` is the text of (:func:`gcode_text`): the text is then read as
        program text, never taken as a path (a one-line program can name a file), and
        :attr:`Program.source` names the file. ``None``: as above.

    Raises
    ------
    GcodeError
        For an unsupported or malformed line, naming the line number and the word.
    """
    if source is not None and not (isinstance(source, str) and isinstance(text_or_path, str)):
        raise WoodcamError(f"read_gcode: source names the file the program text was read from, "
                           f"so it takes the text (str) and a str; got {type(text_or_path).__name__} "
                           f"and {source!r:.60}; pass read_gcode(gcode_text(path), source=str(path))")
    if not isinstance(text_or_path, (str, os.PathLike)):  # None was parsed as the program 'None'
        raise WoodcamError(f"read_gcode: text_or_path must be the program text (str) or a file path; got "
                           f"{text_or_path!r:.60}; pass read_gcode(Path('part.nc')) or the text itself")
    one_line = isinstance(text_or_path, str) and "\n" not in text_or_path
    if source is not None:
        text = str(text_or_path)
    elif isinstance(text_or_path, os.PathLike) or (one_line and (
            Path(text_or_path).suffix.lower() in {".nc", ".gcode", ".ngc", ".tap", ".cnc", ".txt"}
            or _names_a_file(text_or_path))):
        path = Path(text_or_path)
        if not path.is_file():
            raise WoodcamError(f"read_gcode: text_or_path={str(path)!r} is not a file; "
                               "pass an existing G-code file or the program text")
        source, text = str(path), gcode_text(path)
    else:
        source, text = "<string>", str(text_or_path)
    if not (isinstance(chord_tol_mm, numbers.Real) and math.isfinite(chord_tol_mm)
            and chord_tol_mm > 0):
        raise WoodcamError(f"read_gcode: chord_tol_mm must be a finite number > 0, got "
                           f"{chord_tol_mm!r}; use e.g. {ARC_CHORD_TOL_MM}")
    start = DEFAULT_START_MM if start_mm is None else start_mm
    start = as_floats(start)  # 'abc' was numpy's bare ValueError
    start = None if start is None else start.reshape(-1)
    if start is None or start.shape != (3,) or not np.all(np.isfinite(start)):
        raise WoodcamError(f"read_gcode: start_mm must be three finite numbers (mm), got "
                           f"{start_mm!r}; e.g. (0, 0, 10)")
    mzero = None
    if machine_zero_mm is not None:
        mzero = tuple(check_vector(machine_zero_mm, "read_gcode: machine_zero_mm",
                                   fix="give millimetres, e.g. (0, 0, 80), or None").tolist())
    if tool_diameters_mm is not None and not isinstance(tool_diameters_mm, Mapping):
        raise WoodcamError(f"read_gcode: tool_diameters_mm must be a dict of tool number -> "
                           f"diameter (mm) or None; got {tool_diameters_mm!r:.60}; e.g. {{1: 6.35}}")
    diameters = {}
    for number, d in (tool_diameters_mm or {}).items():
        n = int(check_number(number, "read_gcode: tool_diameters_mm's tool number", lo=0,
                             hi=99999, integer=True, fix="key the diameters by tool number"))
        diameters[n] = check_number(d, f"read_gcode: tool_diameters_mm[{n}]", lo=0, lo_open=True,
                                    fix="give the cutter's diameter in mm, e.g. 6.35")
    said: list[tuple[int, str]] = []
    printed: list[tuple[int, str]] = []
    if interpreter == "linuxcnc":
        from .linuxcnc import run_linuxcnc

        moves, warnings = run_linuxcnc(text, start_mm=tuple(start.tolist()),
                                       machine_zero_mm=mzero, said=said, printed=printed,
                                       tool_diameters_mm=diameters)
    elif interpreter == "woodcam":
        interp = Interpreter(text, dialect=dialect, start_mm=start.tolist(),
                             machine_zero_mm=mzero, tool_diameters_mm=diameters)
        moves, warnings = interp.run()
        said, printed = interp.messages, interp.printed
    else:
        raise WoodcamError(f"read_gcode: interpreter must be 'woodcam' or 'linuxcnc', got "
                           f"{interpreter!r}")
    return program_from_canonical(moves, start.tolist(), chord_tol_mm, source,
                                  [f"line {ln}: {m}" for ln, m in warnings],
                                  [f"line {ln}: {m}" for ln, m in said],
                                  [f"line {ln}: {m}" for ln, m in printed])


def program_from_canonical(moves, start_mm, chord_tol_mm, source="<string>",
                           warnings=(), messages=(), printed=()) -> Program:
    """Canonical moves (:mod:`.interpreter`'s form) -> a :class:`Program`: arcs become chords
    with sagitta <= ``chord_tol_mm`` whose vertices lie on the analytic circle/helix."""
    pos = list(map(float, start_mm))
    starts, ends, meta = [], [], []
    for kind, line, end, centre, rot, plane, feed, spindle, tool, inch, *ran in moves:
        ran_line = ran[0] if ran else line  # the main-program line it ran under
        if kind != ARC:
            starts.append(pos)
            ends.append(list(end))
            meta.append((RAPID if kind == 0 else FEED, tool, line, feed, spindle, inch, ran_line))
            pos = list(end)
            continue
        pts = _arc_chords(pos, end, centre, rot, plane, chord_tol_mm, line)
        k = len(pts)
        starts.append(pos)
        starts.extend(pts[:-1].tolist())
        ends.extend(pts.tolist())
        meta.extend([(FEED, tool, line, feed, spindle, inch, ran_line)] * k)
        pos = list(end)
    n = len(meta)
    m = np.array(meta, float).reshape(n, 7)
    s = np.array(starts, float).reshape(n, 3)
    e = np.array(ends, float).reshape(n, 3)
    keep = np.any(s != e, axis=1)  # chords of zero length carry no cut
    s, e, m = s[keep], e[keep], m[keep]
    tools = m[:, 1].astype(int)
    return Program(s, e, m[:, 0].astype(np.uint8), tools, m[:, 2].astype(int), m[:, 3],
                   m[:, 4], source, sorted(set(tools.tolist())), list(warnings),
                   list(messages), list(printed), m[:, 5] != 0, m[:, 6].astype(int))


_PLANE_AXES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}


def _arc_chords(start, end, centre, rot, plane, tol, line) -> np.ndarray:
    """``(k, 3)`` chord end points of one canonical arc (LinuxCNC's ARC_FEED: ``rot`` turns,
    positive counter-clockwise about the plane normal; a full turn when end = start)."""
    a1, a2, an = _PLANE_AXES[plane]
    c = np.array(centre, float)
    p0 = np.array([start[a1], start[a2]])
    p1 = np.array([end[a1], end[a2]])
    r0 = float(np.hypot(*(p0 - c)))
    r1 = float(np.hypot(*(p1 - c)))
    t0 = math.atan2(p0[1] - c[1], p0[0] - c[0])
    t1 = math.atan2(p1[1] - c[1], p1[0] - c[0])
    turns = abs(int(rot))
    if rot < 0:
        sweep = (t1 - t0) % (-2 * math.pi)
        if sweep == 0 or abs(sweep) < 1e-12:
            sweep = -2 * math.pi
        sweep -= 2 * math.pi * (turns - 1)
    else:
        sweep = (t1 - t0) % (2 * math.pi)
        if sweep == 0 or abs(sweep) < 1e-12:
            sweep = 2 * math.pi
        sweep += 2 * math.pi * (turns - 1)
    rmax = max(r0, r1)
    step = 2 * math.acos(max(1 - tol / rmax, -1.0)) if tol < rmax else math.pi
    n_f = abs(sweep) / step - 1e-9 if step > 0 else math.inf
    if not n_f <= MAX_CHORDS_PER_ARC:
        raise GcodeError(line, "G2/G3", f"an arc of radius {say_length(rmax, '.4g')} sweeping "
                         f"{math.degrees(abs(sweep)):.4g} degrees needs more than "
                         f"{MAX_CHORDS_PER_ARC} chords at chord_tol_mm={tol:g}",
                         "check the arc's radius and end point, or raise chord_tol_mm")
    n = max(1, math.ceil(n_f))
    t = np.arange(1, n + 1) / n
    ang = t0 + sweep * t
    rad = r0 + (r1 - r0) * t
    pts = np.empty((n, 3))
    pts[:, a1] = c[0] + rad * np.cos(ang)
    pts[:, a2] = c[1] + rad * np.sin(ang)
    pts[:, an] = start[an] + (end[an] - start[an]) * t
    pts[-1] = end  # exact end point
    if not np.all(np.isfinite(pts)):
        raise GcodeError(line, "G2/G3", "arc points out of range", "check the arc's numbers")
    return pts
