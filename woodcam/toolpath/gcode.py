"""G-code reader: RS274/NGC text -> a :class:`Program` of straight moves in millimetres.

Data form
---------
A :class:`Program` holds ``n`` straight moves as arrays: ``start_mm, end_mm : (n, 3) float`` in
the machine (G-code work) frame, millimetres, whatever ``G20/G21`` the program used;
``kind : (n,) uint8`` (0 = rapid ``G0``, 1 = feed ``G1/G2/G3``), ``tool : (n,) int`` (the tool
number loaded by the last ``M6``, 0 before any), ``line : (n,) int`` (1-based source line) and
``feed_mm_min, spindle_rpm : (n,) float``. Arcs are already split into chords whose sagitta is at
most ``chord_tol_mm`` (default :data:`woodcam.tolerances.ARC_CHORD_TOL_MM`), so every arc vertex
lies exactly on the analytic circle (helix).

What is read
------------
``G0 G1 G2 G3`` (arcs in ``I/J/K`` form, incremental centres, and ``R`` form, full circles with
``I/J/K``, helical arcs), ``G4`` dwell, ``G17/G18/G19`` planes, ``G20/G21`` units,
``G90/G91`` distance mode, ``G90.1/G91.1`` arc-centre mode, the drilling cycles
``G81/G82/G83`` with ``G98/G99`` (expanded to rapid/feed moves, absolute mode only), ``G80``,
``F S T N O`` words, ``M0 M1 M2 M30 M3 M4 M5 M6 M7 M8 M9``, no-op modes
``G40 G49 G54 G61 G64 G94`` and ``G43 H..`` (tools are measured from their tip), ``G28`` and
``G53`` (the named axes go to machine positions outside the work frame and become unknown, see
below), ``( )`` and ``;`` comments, ``%`` lines.
Anything else is an error naming the line and the word.

Start position: the machine position is unknown until the program sets it. Axes start unknown;
a motion that starts from an unknown axis only sets the position (no move is emitted), the usual
``G0 Z5`` / ``G0 X.. Y..`` preamble. Pass ``start_mm`` to start from a known point instead.
After ``G28``/``G53`` the homed axes are unknown again in the same way.

Why a hand-written tokenizer: the maintained PyPI parsers do not fit. ``pygcode`` (last release
0.2.1, 2017) is unmaintained; ``gcodeparser`` (0.3.0) splits a line into one command and a
parameter dict for 3D-printer G-code: one G word per line, no modal state, no source line numbers
in its output, no arcs, no ``( )`` comments, and it silently skips words it does not know, while
we must reject them with the line number. The RS274 subset above is ~200 lines of code here.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._types import ArrayLike, PathLike
from ..errors import WoodcamError
from ..tolerances import ARC_CHORD_TOL_MM, ARC_RADIUS_MISMATCH_MM

MM_PER_INCH = 25.4

RAPID, FEED = 0, 1
_KIND_NAMES = ("rapid", "feed")



#: Modal G codes that only switch a state flag: code -> (attribute, value), applied in this
#: order (a line naming both codes of a pair ends in the second one's state).
_MODAL_FLAGS = {
    90.0: ("incremental", False), 91.0: ("incremental", True),      # distance mode
    90.1: ("arc_absolute", True), 91.1: ("arc_absolute", False),    # arc centre I J K mode
    98.0: ("retract_r", False), 99.0: ("retract_r", True),          # canned-cycle retract
}

class GcodeError(WoodcamError):
    """A G-code line that woodcam cannot read; ``line`` is the 1-based source line."""

    def __init__(self, line: int, word: str, rule: str, fix: str, n_word: int | None = None):
        where = f"line {line}" + (f" (N{n_word})" if n_word is not None else "")
        super().__init__(f"G-code {where}: {word!r}: {rule}; {fix}")
        self.line = line
        self.word = word


@dataclass(frozen=True)
class Move:
    """One straight move. ``start_mm, end_mm : (3,)`` machine frame, mm."""

    start_mm: tuple[float, float, float]
    end_mm: tuple[float, float, float]
    kind: str  # "rapid" | "feed"
    tool: int
    line: int
    feed_mm_min: float
    spindle_rpm: float


@dataclass
class Program:
    """Straight moves of a G-code program as arrays (see the module docstring for the form)."""

    start_mm: np.ndarray
    end_mm: np.ndarray
    kind: np.ndarray
    tool: np.ndarray
    line: np.ndarray
    feed_mm_min: np.ndarray
    spindle_rpm: np.ndarray
    source: str = "<string>"
    tool_numbers: list[int] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.kind)

    def __getitem__(self, i: int) -> Move:
        return Move(tuple(map(float, self.start_mm[i])), tuple(map(float, self.end_mm[i])),
                    _KIND_NAMES[int(self.kind[i])], int(self.tool[i]), int(self.line[i]),
                    float(self.feed_mm_min[i]), float(self.spindle_rpm[i]))

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    @property
    def moves(self) -> list[Move]:
        return list(self)

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


# A word is a letter and a real number; whitespace is allowed between them (RS274NGC 3.3).
_WORD = re.compile(r"([A-Za-z])\s*([+-]?(?:\d+\.?\d*|\.\d+))")
_COMMENT = re.compile(r"\([^()]*\)")

_G_MOTION = {0.0, 1.0, 2.0, 3.0, 80.0, 81.0, 82.0, 83.0}
_G_NOOP = {40.0, 49.0, 54.0, 61.0, 64.0, 94.0, 43.0}
_G_KNOWN = _G_MOTION | _G_NOOP | {4.0, 17.0, 18.0, 19.0, 20.0, 21.0, 28.0, 53.0, 90.0, 91.0,
                                  90.1, 91.1, 98.0, 99.0}
_G_GROUPS = {  # modal groups: two words of one group in a block is an error
    "motion": _G_MOTION, "plane": {17.0, 18.0, 19.0}, "units": {20.0, 21.0},
    "distance": {90.0, 91.0}, "arc distance": {90.1, 91.1}, "retract": {98.0, 99.0},
}
_M_KNOWN = {0, 1, 2, 30, 3, 4, 5, 6, 7, 8, 9}
_VALUE_WORDS = set("XYZIJKRPQFSTH")
# (first, second, normal) axis indices of the arc planes; first x second = normal (right-handed)
_PLANES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}
_PLANE_CENTRE_WORDS = {17: "IJ", 18: "KI", 19: "JK"}


def _fmt(letter: str, value: float) -> str:
    return f"{letter}{value:g}"


def read_gcode(text_or_path: str | PathLike, *, chord_tol_mm: float = ARC_CHORD_TOL_MM,
               start_mm: ArrayLike | None = None) -> Program:
    """Read G-code text or a file path into a :class:`Program` of straight moves (mm).

    Parameters
    ----------
    text_or_path : str | os.PathLike
        Program text, or the path of a ``.nc/.gcode/.ngc/.tap`` file. A ``str`` containing a
        newline or a G-code word is taken as text.
    chord_tol_mm : float
        Largest sagitta (mm) between an arc and its chords.
    start_mm : (3,) float | None
        Known start position in the machine frame (mm); ``None``: unknown (module docstring).

    Raises
    ------
    GcodeError
        For an unsupported or malformed line, naming the line number and the word.
    """
    source = "<string>"
    if isinstance(text_or_path, Path) or (isinstance(text_or_path, str) and "\n" not in text_or_path
                                          and Path(text_or_path).suffix.lower()
                                          in {".nc", ".gcode", ".ngc", ".tap", ".cnc", ".txt"}):
        path = Path(text_or_path)
        if not path.is_file():
            raise WoodcamError(f"read_gcode: text_or_path={str(path)!r} is not a file; "
                               "pass an existing G-code file or the program text")
        source, text = str(path), path.read_text(errors="replace")
    else:
        text = str(text_or_path)
    if not chord_tol_mm > 0:
        raise WoodcamError(f"read_gcode: chord_tol_mm must be > 0, got {chord_tol_mm!r}; "
                           f"use e.g. {ARC_CHORD_TOL_MM}")
    return _Reader(chord_tol_mm, start_mm).run(text, source)


class _Reader:
    """Modal interpreter state. Runs once per program; per-line work is small Python."""

    def __init__(self, chord_tol_mm, start_mm):
        self.tol = float(chord_tol_mm)
        self.pos = ([math.nan] * 3 if start_mm is None
                    else [float(v) for v in np.asarray(start_mm, float).reshape(3)])
        self.motion = None
        self.plane = 17
        self.scale = 1.0  # mm per program unit
        self.incremental = False
        self.arc_absolute = False
        self.retract_r = False  # G99 (retract to R) else G98 (retract to initial Z)
        self.feed = math.nan
        self.spindle = 0.0
        self.selected_tool = 0
        self.tool = 0
        self.ended = False
        self.out_s: list = []
        self.out_e: list = []
        self.out_meta: list = []  # (kind, tool, line, feed, spindle)
        self.tools_used: set[int] = set()
        self.cycle_q = math.nan
        self.cycle_r = math.nan

    # -- output ---------------------------------------------------------------------------
    def _emit(self, end, kind, line):
        """Move to ``end`` (3 floats, NaN = axis not given). Plain floats: called per line."""
        pos = self.pos
        new = [p if math.isnan(e) else e for p, e in zip(pos, end)]
        if any(math.isnan(p) for p in pos):
            self.pos = new
            return
        if new != pos:
            self.out_s.append(pos)
            self.out_e.append(new)
            self.out_meta.append((kind, self.tool, line, self.feed, self.spindle))
            self.tools_used.add(self.tool)
        self.pos = new

    def run(self, text: str, source: str) -> Program:
        for lineno, raw in enumerate(text.splitlines(), start=1):
            if self.ended:
                break
            self._line(lineno, raw)
        n = len(self.out_meta)
        meta = np.array(self.out_meta, float).reshape(n, 5)
        return Program(
            np.array(self.out_s, float).reshape(n, 3), np.array(self.out_e, float).reshape(n, 3),
            meta[:, 0].astype(np.uint8), meta[:, 1].astype(int), meta[:, 2].astype(int),
            meta[:, 3], meta[:, 4], source, sorted(self.tools_used))

    # -- one block ------------------------------------------------------------------------
    def _line(self, lineno: int, raw: str):
        body = raw.split(";", 1)[0]
        body = _COMMENT.sub(" ", body)
        if "(" in body or ")" in body:
            bad = "(" if "(" in body else ")"
            raise GcodeError(lineno, bad, "unbalanced or nested comment parenthesis",
                             "close every '(' with ')' on the same line, without nesting")
        body = body.strip()
        if body.startswith("/"):  # block delete: we run with the switch off
            body = body[1:].strip()
        if not body or body == "%":
            return
        words: list[tuple[str, float, str]] = []
        pos = 0
        for m in _WORD.finditer(body):
            gap = body[pos:m.start()].strip()
            if gap:
                raise GcodeError(lineno, gap, "malformed word (a word is a letter and a number)",
                                 "fix or remove the text")
            words.append((m.group(1).upper(), float(m.group(2)), m.group(0).replace(" ", "")))
            pos = m.end()
        if body[pos:].strip():
            raise GcodeError(lineno, body[pos:].strip(),
                             "malformed word (a word is a letter and a number)",
                             "fix or remove the text")
        n_word = None
        g: list[tuple[float, str]] = []
        m_: list[tuple[int, str]] = []
        vals: dict[str, float] = {}
        for letter, value, tok in words:
            if letter == "N":
                n_word = int(value)
            elif letter == "O":  # program number (Fanuc-style posts): nothing to do
                continue
            elif letter == "G":
                v = round(value, 1)
                if v not in _G_KNOWN:
                    raise GcodeError(lineno, tok, "unsupported G code (woodcam reads G0-G4, "
                                     "G17-G21, G28, G40, G43, G49, G53, G54, G61, G64, G80-G83, "
                                     "G90, G91, "
                                     "G90.1, G91.1, G94, G98, G99)",
                                     "post-process the program for a 3-axis mill with these "
                                     "codes", n_word)
                g.append((v, tok))
            elif letter == "M":
                if value not in _M_KNOWN:
                    raise GcodeError(lineno, tok, "unsupported M code (woodcam reads M0-M9, M30)",
                                     "remove it or post-process for a 3-axis mill", n_word)
                m_.append((int(value), tok))
            elif letter in _VALUE_WORDS:
                if letter in vals:
                    raise GcodeError(lineno, tok, f"word {letter} appears twice in one block",
                                     "keep one", n_word)
                vals[letter] = value
            else:
                raise GcodeError(lineno, tok, f"unsupported word {letter} (woodcam simulates a "
                                 "3-axis mill: no A/B/C/U/V/W axes or other letters)",
                                 "post-process for 3 axes", n_word)
        for group, codes in (_G_GROUPS.items() if len(g) > 1 else ()):
            hits = [tok for v, tok in g if v in codes]
            if len(hits) > 1:
                raise GcodeError(lineno, " ".join(hits), f"two {group} G codes in one block",
                                 "keep one", n_word)
        gv = {v for v, _ in g}
        mv = {v for v, _ in m_}
        err = lambda tok, rule, fix: GcodeError(lineno, tok, rule, fix, n_word)  # noqa: E731

        # Order of execution (RS274NGC 3.8): units first here so F is read in the new units.
        if 20.0 in gv:
            self.scale = MM_PER_INCH
        if 21.0 in gv:
            self.scale = 1.0
        if "F" in vals:
            if vals["F"] <= 0:
                raise err(_fmt("F", vals["F"]), "feed rate must be > 0", "give a positive F")
            self.feed = vals["F"] * self.scale
        if "S" in vals:
            self.spindle = vals["S"]
        if "T" in vals:
            self.selected_tool = int(vals["T"])
        if 6 in mv:
            self.tool = self.selected_tool
        for code in (17, 18, 19):
            if float(code) in gv:
                self.plane = code
        for code, (attr, value) in _MODAL_FLAGS.items():
            if code in gv:
                setattr(self, attr, value)
        if 43.0 in gv and "H" not in vals:
            raise err("G43", "G43 needs an H word", "write G43 Hn or remove it")
        if 4.0 in gv:  # dwell: no motion; P is its time and not an axis word here
            vals.pop("P", None)
            if any(k in vals for k in "XYZIJKR"):
                raise err("G4", "G4 dwell takes no axis words", "move on a separate line")
            return
        if 28.0 in gv or 53.0 in gv:
            self._home(gv, vals, lineno, err)
            return
        motion = [v for v in gv if v in _G_MOTION]
        if motion:
            self.motion = motion[0]
            if motion[0] == 80.0:
                self.motion = None
        axis_given = any(k in vals for k in "XYZ")
        if axis_given or (motion and self.motion is not None and self.motion >= 81):
            if self.motion is None:
                raise err(next(tok for l, _, tok in words if l in "XYZ"),
                          "axis word without an active motion mode (G80 cancelled it)",
                          "start the line with G0 or G1")
            self._motion(lineno, vals, err)
        elif any(k in vals for k in "IJKR"):
            tok = next(tok for l, _, tok in words if l in "IJKR")
            raise err(tok, "arc words without an end point", "give X/Y/Z with G2/G3")
        if mv & {2, 30}:
            self.ended = True

    def _home(self, gv, vals, lineno, err):
        """G28 (rapid via an intermediate point to machine home) and G53 (a move in machine
        coordinates): machine home and machine coordinates are not in the work frame, so the
        named axes (all three for a bare G28) become unknown again, as at program start; the
        next moves re-establish them (module docstring)."""
        axes = [a for a in "XYZ" if a in vals]
        if 28.0 in gv:
            if axes:
                self._emit(self._target(vals, err), RAPID, lineno)  # the intermediate point
            else:
                axes = list("XYZ")
        elif not axes:
            raise err("G53", "G53 without axis words", "give the machine-coordinate target")
        self.pos = [math.nan if a in axes else p for a, p in zip("XYZ", self.pos)]

    def _target(self, vals, err):
        end = list(self.pos)
        for i, a in enumerate("XYZ"):
            if a in vals:
                v = vals[a] * self.scale
                if self.incremental:
                    if math.isnan(self.pos[i]):
                        raise err(_fmt(a, vals[a]), f"incremental (G91) move before the {a} "
                                  "position is known", "start with an absolute (G90) move")
                    end[i] = self.pos[i] + v
                else:
                    end[i] = v
        return end

    def _motion(self, lineno, vals, err):
        mode = self.motion
        if mode in (1.0, 2.0, 3.0, 81.0, 82.0, 83.0) and math.isnan(self.feed):
            raise err(f"G{mode:g}", "feed move before any feed rate F", "set F before cutting")
        if mode >= 81:
            return self._cycle(lineno, vals, err)
        end = self._target(vals, err)
        if mode in (0.0, 1.0):
            if "R" in vals or any(k in vals for k in "IJK"):
                raise err(next(k for k in "IJKR" if k in vals) + f"{vals.get('R', 0):g}",
                          "arc word on a straight move", "use G2/G3 for arcs")
            self._emit(end, RAPID if mode == 0.0 else FEED, lineno)
            return
        self._arc(lineno, vals, end, cw=(mode == 2.0), err=err)

    def _arc(self, lineno, vals, end, cw, err):
        a1, a2, an = _PLANES[self.plane]
        start = np.array(self.pos)
        if np.isnan(start).any():
            raise err(f"G{2 if cw else 3}", "arc before the start position is known",
                      "move to the arc start with G0/G1 first")
        wrong = set("IJK") - set(_PLANE_CENTRE_WORDS[self.plane])
        for k in wrong:
            if k in vals:
                raise err(f"{k}{vals[k]:g}", f"centre word {k} is not in plane G{self.plane}",
                          f"use {'/'.join(_PLANE_CENTRE_WORDS[self.plane])} or change plane")
        p0 = np.array([start[a1], start[a2]])
        p1 = np.array([end[a1], end[a2]])
        if "R" in vals:
            if any(k in vals for k in "IJK"):
                raise err(f"R{vals['R']:g}", "both R and I/J/K on one arc", "give one form")
            r = vals["R"] * self.scale
            d = p1 - p0
            dist = float(np.hypot(*d))
            if dist < 1e-9:
                raise err(f"R{vals['R']:g}", "R-form arc with end = start (a full circle has "
                          "no unique centre)", "use the I/J/K form for full circles")
            if abs(r) < dist / 2 - ARC_RADIUS_MISMATCH_MM:
                raise err(f"R{vals['R']:g}", f"radius {abs(r):g} mm is shorter than half the "
                          f"chord {dist / 2:g} mm", "fix R or the end point")
            # Centre of an R-form arc (grbl/LinuxCNC convention): negative R means > 180 deg.
            h = math.sqrt(max(r * r - dist * dist / 4, 0.0)) / dist
            h = -h if cw else h
            h = -h if r < 0 else h
            centre = p0 + d / 2 + h * np.array([-d[1], d[0]])
        else:
            off = np.zeros(2)
            names = _PLANE_CENTRE_WORDS[self.plane]
            if not any(k in vals for k in names):
                raise err(f"G{2 if cw else 3}", f"arc needs R or {'/'.join(names)}",
                          "give the arc centre")
            for i, k in enumerate(names):
                if k in vals:
                    off[i] = vals[k] * self.scale
            if self.arc_absolute:  # G90.1: centre given in absolute coordinates
                centre = np.array([off[0] if names[0] in vals else p0[0],
                                   off[1] if names[1] in vals else p0[1]])
            else:
                centre = p0 + off
        r0 = float(np.hypot(*(p0 - centre)))
        r1 = float(np.hypot(*(p1 - centre)))
        if abs(r1 - r0) > ARC_RADIUS_MISMATCH_MM + 1e-4 * r0 or r0 < 1e-9:
            raise err(f"G{2 if cw else 3}", f"arc start radius {r0:.4f} mm and end radius "
                      f"{r1:.4f} mm differ by more than {ARC_RADIUS_MISMATCH_MM} mm",
                      "fix the centre (I/J/K) or the end point")
        t0 = math.atan2(p0[1] - centre[1], p0[0] - centre[0])
        t1 = math.atan2(p1[1] - centre[1], p1[0] - centre[0])
        sweep = t1 - t0
        if cw:
            sweep = sweep % (-2 * math.pi)
            if sweep == 0 or abs(sweep) < 1e-12:
                sweep = -2 * math.pi  # end == start with I/J/K: a full circle
        else:
            sweep = sweep % (2 * math.pi)
            if sweep == 0 or abs(sweep) < 1e-12:
                sweep = 2 * math.pi
        rmax = max(r0, r1)
        step = 2 * math.acos(max(1 - self.tol / rmax, -1.0)) if self.tol < rmax else math.pi
        n = max(1, math.ceil(abs(sweep) / step - 1e-9))
        t = np.arange(1, n + 1) / n
        ang = t0 + sweep * t
        rad = r0 + (r1 - r0) * t
        pts = np.empty((n, 3))
        pts[:, a1] = centre[0] + rad * np.cos(ang)
        pts[:, a2] = centre[1] + rad * np.sin(ang)
        pts[:, an] = start[an] + (end[an] - start[an]) * t
        pts[-1] = end  # exact end point
        for p in pts.tolist():
            self._emit(p, FEED, lineno)

    def _cycle(self, lineno, vals, err):
        """G81/G82/G83 at the given X/Y: rapid to R, feed (pecking for G83) to Z, retract."""
        code = f"G{self.motion:g}"
        if self.incremental:
            raise err(code, "drilling cycles in incremental mode (G91) are not supported",
                      "use G90 for the cycle")
        if self.plane != 17:
            raise err(code, "drilling cycles need plane G17", "switch to G17")
        if "R" in vals:
            self.cycle_r = vals["R"] * self.scale
        if "Q" in vals:
            self.cycle_q = abs(vals["Q"]) * self.scale
        if "Z" in vals:
            self.cycle_z = vals["Z"] * self.scale
        if math.isnan(self.cycle_r) or not hasattr(self, "cycle_z"):
            raise err(code, "drilling cycle without R and Z", "give R (retract) and Z (depth)")
        if self.motion == 83.0 and math.isnan(self.cycle_q):
            raise err(code, "G83 needs a peck depth Q", "give Q > 0")
        if any(math.isnan(v) for v in self.pos):
            raise err(code, "drilling cycle before the start position is known",
                      "move above the first hole with G0 first")
        z_init = self.pos[2]
        r, zb = self.cycle_r, self.cycle_z
        x = vals["X"] * self.scale if "X" in vals else self.pos[0]
        y = vals["Y"] * self.scale if "Y" in vals else self.pos[1]
        clear = max(z_init, r)
        self._emit([x, y, clear], RAPID, lineno)
        self._emit([x, y, r], RAPID, lineno)
        if self.motion == 83.0:
            depth = r
            while depth > zb + 1e-9:
                depth = max(depth - self.cycle_q, zb)
                self._emit([x, y, depth], FEED, lineno)
                if depth > zb + 1e-9:
                    self._emit([x, y, r], RAPID, lineno)
                    self._emit([x, y, min(depth + 0.5, r)], RAPID, lineno)  # RS274 clearance
        else:
            self._emit([x, y, zb], FEED, lineno)
        self._emit([x, y, r if self.retract_r else clear], RAPID, lineno)
