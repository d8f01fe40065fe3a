"""The RS274/NGC language as LinuxCNC 2.9 runs it: program text -> canonical moves.

What it reads (LinuxCNC's "G-code overview" and "O codes" chapters)
--------------------------------------------------------------------
- numbered parameters ``#1``-``#5601`` (``#1``-``#30`` local to a subroutine call), named local
  ``#<name>`` and global ``#<_name>`` parameters, indirect ``##1`` / ``#[1+2]``; system
  parameters: coordinate systems ``#5221``... (G54 at 5221, each next one 20 higher), G92
  ``#5210``-``#5213``, G28/G30 homes ``#5161``/``#5181``, ``#5220`` (active system),
  ``#5400`` (loaded tool), ``#5420``-``#5428`` (current position, program units and frame,
  as ``#<_x>``...; A-W read 0: woodcam has no such axes), ``#5599`` (1), ``#5600``/``#5601``
  (0: no tool-changer faults), ``#<_value>`` and ``#<_value_returned>`` (the value of the last
  ``return [v]`` or ``endsub [v]``, and 1 if it had one; LinuxCNC reads a definition's
  ``return [v]`` lines and its ``endsub [v]``, in order, as it passes over it, and so does
  woodcam), LinuxCNC 2.9's other predefined
  named parameters (:data:`_PREDEFINED`: modes, spindle, coolant, overrides, tools, call
  level, version; ``#<_task>`` is 1, the machine's value; the tool changer's pockets and
  ``#<_vminor>`` are refused: woodcam cannot know them); read-only ones (``#5400``-``#5413``,
  ``#5420``-``#5428``, the predefined named ones) cannot be assigned, as in
  LinuxCNC, nor can ``#5600``/``#5601`` (LinuxCNC takes the assignment and reads the machine's
  value over it: the value would be dropped); reading what woodcam cannot know is refused: the
  tool table's offsets and diameter ``#5401``-``#5413``, and probe (``#5061``-``#5070``) or
  input (``#5399``) results the program did not assign (in a
  DEBUG/PRINT text a tool-table entry shows as ``[#5403: T1's Z offset, from the machine's
  tool table]``, ``#5410`` as the loaded tool's diameter where ``tool_diameters_mm`` has it,
  every entry as 0 with no tool loaded, before the first M6, as LinuxCNC;
  the
  ``params`` argument may supply them; the machine's state, ``#5400``-``#5413``,
  ``#5420``-``#5428``, ``#5600``/``#5601``, it refuses); lengths
  are millimetres whatever
  ``G20/G21`` (LinuxCNC on a metric machine: the machine's units), so ``G28`` in a ``G20``
  program returns to the stored home and a ``G20`` program reads ``#5221`` in mm;
- expressions ``[...]`` with ``** * / mod + - eq ne gt ge lt le and or xor`` (LinuxCNC's six
  precedence levels, all left-associative; ``eq``/``ne`` within 1e-4 as LinuxCNC),
  unary minus, functions ``sin cos tan asin acos atan[a]/[b] sqrt abs round fix fup exp ln
  exists`` (degrees);
- parameter assignments take effect after the whole line was read (``#1=6 G0 X#1`` moves to the
  old ``#1``);
- O-words: ``sub/endsub/call/return``, ``if/elseif/else/endif``, ``while/endwhile``,
  ``do/while``, ``repeat/endrepeat``, ``break``, ``continue`` (the first word of its line,
  after any N word: after a comment LinuxCNC reads none, so such a line opens or closes
  nothing, is refused when reached and warned about when skipped); at most
  :data:`MAX_CALL_DEPTH` nested calls (LinuxCNC's limit) and :data:`MAX_BLOCKS` executed lines
  (woodcam's guard against endless loops); a subroutine is defined where the program passes
  over its definition, a call before that runs the first definition after the call (LinuxCNC
  searches the file forward), and a definition reached for a label already defined (a second
  definition, or the one a call found or a loop passed) is refused, as LinuxCNC 2.9 does;
  so is an if/while/do/repeat line reached with a label another such line reached before holds
  (labels are kept per subroutine, subprogram or main program, across calls: 'duplicate O-word
  label'; a second do loop's test would go back to the first do); as LinuxCNC, an endsub or
  return outside every definition is refused when reached, and a sub defined inside another,
  one never closed and text after ``oN sub`` when the program passes over the definition (the
  moves before run; after M2 or in a branch not taken, never), text after an endsub's value
  only when a call returns there (passing over, the value alone is read);
- Fanuc-style subprograms (LinuxCNC 2.9's "Fanuc-Style Numbered Programs", measured against
  its interpreter): ``M98 P1000 L2`` (the first word of its line, before any comment, as
  ``O`` words and the returning ``M99``; only P and L on it) calls
  the subprogram that starts at the line ``O1000`` twice (no L: once; ``L0``: not at all), and
  ``M99``, alone first on its line, returns; the M98 line runs again for each repeat (P read
  again, L once); ``#1``-``#30`` are the caller's (not saved or restored, unlike ``call``),
  named parameters the call's own; nested M98 and o-word calls share the :data:`MAX_CALL_DEPTH`
  limit, and the two kinds do not mix (``M98`` calls no ``o100 sub``, an ``o100 sub`` holds no
  ``O``/``M99`` line). An ``O1000`` line reached without a call is run through, as a program
  number. LinuxCNC finds the ``O1000`` line by searching forward from the first M98 that calls
  it (a label before that call is refused); ``fanuc`` keeps its programs apart: the one
  ``O1000`` line wherever it is, and ``M98 P51000`` without L is ``O1000`` five times (Fanuc's
  count-and-4-digit form) when the file has no ``O51000``. ``M99`` in the main program starts
  it again forever on a machine: woodcam simulates one pass and warns;
- ``G0 G1 G2 G3`` (I/J/K and R arcs in the three planes, ``P`` turns; in ``linuxcnc`` a line
  of I/J/K alone under a modal G2/G3 is a full circle, a G2/G3 with neither end nor centre
  words an error, as LinuxCNC runs them), ``G4``, ``G10 L2/L20``,
  ``G17-G19``, ``G20/G21``, ``G28/G28.1/G30/G30.1``, ``G40``, ``G43/G43.1/G49`` (woodcam tools
  are measured from the tip and the moves are the tip's, so an offset does not move where a
  program coordinate cuts; as LinuxCNC, the spindle stands still when the offset changes, so
  the tip moves by the change: ``G43.1 Z1`` then ``G91 G0 Z-1`` from Z10 ends at Z8, and
  ``G53``, ``G28``/``G30`` homes and ``G28.1`` place the spindle, the tip the offset lower;
  ``G43 H`` takes the tool table's length as 0), ``G53``,
  ``G54-G59.3``, ``G52`` (the G92 offset set to its words, as LinuxCNC), ``G61/G61.1/G64``,
  ``G73 G81 G82 G83 G85 G86 G89`` with ``G98/G99`` and ``L`` (in ``linuxcnc`` R, Z, Q and P
  carry over only between lines of one cycle code, as LinuxCNC),
  ``G80``, ``G90/G91``, ``G90.1/G91.1``, ``G92/G92.1/G92.2/G92.3``, ``G94``, ``G97``;
  ``M0 M1 M2 M3 M4 M5 M6 M7 M8 M9 M30 M48-M53 M60`` (one of each modal group a line; in
  ``linuxcnc`` M6 stops the spindle, as LinuxCNC's tool change does);
  ``F S T``, ``E`` (beside ``M66``-``M68``), ``N`` (digits, the first word of a line, before any
  comment; grbl: anywhere); ``( )``/``;`` comments, ``(msg,...)`` and ``(debug,...)`` (operator
  messages, the parameters' values put in, as
  LinuxCNC: :attr:`Interpreter.messages`), ``(print,...)`` (the same, but what LinuxCNC writes
  to its terminal, not its screen: :attr:`Interpreter.printed`; one a pass in a loop, a value
  woodcam cannot know in it warned once for its line), ``(abort,...)`` (an error, as LinuxCNC),
  block delete ``/`` (switch off, as LinuxCNC's default), ``%`` delimiters (a line of its own:
  the first non-blank line opens, the next ends the program; any other ``%`` is an error, as in
  LinuxCNC).

Everything else is an error naming the line and the word; what is read but has no effect on the
cut is silent, what is read and could matter but is not simulated is a warning with its line
(once per line in a loop or a subroutine, counting the passes: ``(warned once; the line ran
500 times)``).

Dialects: ``linuxcnc`` (the default) is the reference. ``grbl`` has no parameters, expressions,
O-words or subprograms (they are errors there, ``O1234`` and ``M98`` too), needs no ``M2``.
``fanuc`` starts in ``G0`` and needs no ``M2`` either. ``O1234`` program-number lines and
``M98``/``M99`` subprograms are read in ``linuxcnc`` and ``fanuc``, as is ``G80`` beside a
motion code (Fanuc keeps canned cycles in their own group, as in the ``G00 G80 G40 G49`` safety
line; LinuxCNC 2.9 accepts it too).

Output: canonical moves in the G-code frame, millimetres, tool tip: the G54 work frame as the
machine has it before the program runs (the frame of ``start_mm``). Where the machine's own
origin (``G53``) lies in it is ``machine_zero_mm``: the default ``(0, 0, 0)`` is LinuxCNC with
every offset zero (the machine frame is the G54 frame; the oracle's setting); a given point
``M`` is LinuxCNC with the G54 offset ``-M`` (LinuxCNC keeps the G54 origin's position in
machine coordinates, so the machine origin lies at ``-offset`` in G54), the machine frame
shifted by ``M`` on output; ``None`` (not known) reads a ``G53`` Z move as a retract to the
start height (``start_mm`` Z, or the tool's Z if higher; posts write ``G53 G0 Z-5`` or ``G53
G0 Z0`` for "near the top of Z travel", which in machine coordinates is no place in the work
frame) and a ``G53`` X/Y with machine zero at G-code zero, each warned once with its lines.
A canonical move is
``(kind, line, end (3,), centre (2,) | None, rotation, plane, feed_mm_min, spindle_rpm, tool,
inch, ran_line)``: ``kind`` 0 = traverse, 1 = feed, 2 = arc (``centre`` in the plane's first/second
axes, ``rotation`` = +/-turns, + counter-clockwise, as LinuxCNC's ``ARC_FEED``); ``inch``: the
move was programmed in ``G20`` (its lengths as written are inches; the move is in mm all the
same); ``ran_line``: the main-program line it ran under (``line`` itself, or for a move of a
subroutine or M98 subprogram the line of the outermost call that ran it); ``ran_line`` may be
left off (it is then ``line``).

Why hand-written: no maintained PyPI package interprets this language. ``pygcode`` (0.2.1,
2017, unmaintained) and ``gcodeparser`` parse words but have no parameters, expressions or
O-word control flow; LinuxCNC's own interpreter is C++ inside the ``linuxcnc-uspace`` Debian
package (not on PyPI) and is used as the test oracle and as ``--interpreter linuxcnc``
(:mod:`woodcam.toolpath.linuxcnc`).
"""

from __future__ import annotations

import math
import re
from typing import Callable, Literal

from ..errors import WoodcamError
from ..units import say_length

Dialect = Literal["linuxcnc", "grbl", "fanuc"]
DIALECTS: tuple[str, ...] = ("linuxcnc", "grbl", "fanuc")

#: LinuxCNC's error at the end of a file without M2/M30 (``NO_PERCENT``: one that opened with a
#: '%' line and has no closing one); woodcam warns of it and keeps the moves before it, which
#: the machine has cut by then
NO_END = "File ended with no percent sign or program end"
NO_PERCENT = "File ended with no percent sign"
#: LinuxCNC refuses a tenth nested subroutine call ("Too many subroutine levels").
MAX_CALL_DEPTH = 9
#: Executed lines before woodcam stops a program as an endless loop (a 35,000-line relief runs
#: 35,000; loops that engrave text a few 10,000): ~10 s of CPU at ~50,000 lines/s.
MAX_BLOCKS = 500_000
#: Canonical moves before woodcam stops (the largest public program here has ~67,000).
MAX_MOVES = 1_000_000
#: Canned-cycle repeats (L) one block may ask for.
MAX_CYCLE_REPEATS = 10_000
MM_PER_INCH = 25.4
#: LinuxCNC's G73/G83 retract clearance above the previous peck, 0.010 inch.
_RAPID_DELTA_IN = 0.010
#: LinuxCNC's eq/ne tolerance.
_EQ_TOL = 1e-4
#: LinuxCNC's centre-arc radius tolerances: CENTER_ARC_RADIUS_TOLERANCE_INCH = 2 * 0.001 * sqrt 2
#: (inch), _MM = 2 * 0.01 * sqrt 2 (mm), relative 0.1 %; an arc whose end radius differs by
#: more than 100 x the absolute, or by more than both, is refused (measured against LinuxCNC
#: 2.9: 0.028 mm on a 10 mm radius is read, 0.029 mm refused).
_ARC_ABS_TOL = {"in": 2 * 0.001 * math.sqrt(2), "mm": 2 * 0.01 * math.sqrt(2)}
_ARC_REL_TOL = 0.001
#: LinuxCNC refuses a centre-format arc whose start or end radius is below 0.00005 inch
#: ("Zero-radius arc"; measured against LinuxCNC 2.9: 0.00126 mm refused, 0.00128 mm read).
_ARC_MIN_RADIUS_MM = 0.00005 * 25.4
#: LinuxCNC refuses an R-format arc whose half chord exceeds |R| by more than 0.00005 inch
#: ("Arc radius too small to reach end point"), in G20 and G21 alike (measured against
#: LinuxCNC 2.9: R 0.00126 mm short of the half chord is read, 0.00128 mm refused; in inch
#: 0.000049 read, 0.000051 refused); within it the centre is the chord's midpoint.
_ARC_R_TOL_MM = 0.00005 * 25.4

TRAVERSE, FEED, ARC = 0, 1, 2


#: Deepest nesting of brackets, unary signs and functions one G-code expression may have.
MAX_EXPR_DEPTH = 100


#: grbl's ``$`` system commands (grbl 1.1 "Commands"): (line start, what it does, the fix).
_GRBL_SYSTEM = (
    ("$h", "homing: the machine drives to its home switches",
     "remove the line and home the machine before the job (woodcam starts the tool at --start)"),
    ("$j=", "jog: a move in the jog's own words", "write the move as a G0/G1 line"),
    ("$x", "alarm unlock", "remove the line (it does not move the machine)"),
    ("$c", "check mode: the controller then parses without moving",
     "remove the line (a checked program cuts nothing)"),
    ("$rst=", "settings reset", "remove the line"),
    ("$slp", "sleep", "remove the line"),
    ("<n>=", "a setting change", "remove the line and set the controller beforehand"),
)  # any other: a settings, state or build report ($$, $#, $G, $I, $N)


class GcodeError(WoodcamError):
    """A G-code line that woodcam refuses; ``line`` is the 1-based source line."""

    def __init__(self, line: int, word: str, rule: str, fix: str, source: str | None = None):
        where = f"{source}: G-code line" if source else "G-code line"
        super().__init__(f"{where} {line}: {word!r}: {rule}; {fix}")
        self.line = line
        self.word = word
        self.rule = rule
        self.fix = fix


# ------------------------------------------------------------------------------------------
# words
_NUM = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)")
_OWORD = re.compile(r"(?:n\d+(?:\.\d+)?)?o(<[^>]*>|\d+)([a-z]+)(.*)$")
#: LinuxCNC's line number: digits, optionally '.' and more digits ("N5", "N5.1"; it refuses
#: "N-5", "N+5", "N5.", "N.5", "N#1" with "Bad format unsigned integer").
_LINE_NUMBER = re.compile(r"\d+(?:\.\d+)?(?!\.)")
_N_WORD = re.compile(r"n[^a-z]*")  # an N word as written, for the message
_ONUMBER = re.compile(r"(?:n\d+)?o\d+$")
#: A Fanuc-style subprogram call or return: M98 or M99 as the first word of the line (after its
#: N word); LinuxCNC reads only such a line as one ("G0 X1 M98 P100": "Unknown m code used").
_M98_M99 = re.compile(r"(?:n\d+(?:\.\d+)?)?m0*(98|99)(?![\d.])(.*)$")
#: The same with a decimal point ("M98.0"): LinuxCNC reads neither as a call or return.
_M98_M99_DECIMAL = re.compile(r"(?:n\d+(?:\.\d+)?)?(m0*(?:98|99)\.\d*)")
#: Words of a plain move line ("X12.5 Z-1.2 F900" in G0/G1): :meth:`Interpreter.execute`
#: runs them on a short path (the raster lines of a relief program are nearly all such lines).
_PLAIN_WORDS = frozenset("xyzf")
#: A line of nothing but X/Y/Z/F words with plain numbers (most lines of a CAM program): read
#: by one regex instead of the character loop (same numbers as _NUM; anything else, a repeated
#: word included, takes the general path and its errors).
_PLAIN_LINE = re.compile(r"(?:[xyzf][+-]?(?:\d+\.?\d*|\.\d+))+")
_PLAIN_WORD = re.compile(r"([xyzf])([+-]?(?:\d+\.?\d*|\.\d+))")
_NAME = re.compile(r"<([^>]*)>")
_FUNCS = ("atan", "asin", "acos", "abs", "cos", "sin", "tan", "sqrt", "round", "fix", "fup",
          "exp", "ln", "exists")
_BINOPS = (("**", 6), ("*", 5), ("/", 5), ("mod", 5), ("+", 4), ("-", 4), ("eq", 3), ("ne", 3),
           ("gt", 3), ("ge", 3), ("lt", 3), ("le", 3), ("and", 2), ("or", 2), ("xor", 2))
_OKEYS = ("sub", "endsub", "call", "return", "if", "elseif", "else", "endif", "while",
          "endwhile", "do", "repeat", "endrepeat", "break", "continue")
# the words a 3-axis mill program may carry (D only beside cutter compensation, which is
# refused by its G code: a "G41 D1" line names G41, not an unknown letter; E only beside
# LinuxCNC's analog I/O M66/M67/M68, "M67 E0 Q50" setting a laser's or plasma's power)
_LETTERS = set("dfgmnstxyzijkrpqlhe")
_MOTION = {0.0, 1.0, 2.0, 3.0, 73.0, 80.0, 81.0, 82.0, 83.0, 85.0, 86.0, 89.0}
_CYCLES = {73.0, 81.0, 82.0, 83.0, 85.0, 86.0, 89.0}
_G_GROUPS = {
    "motion": _MOTION, "plane": {17.0, 18.0, 19.0}, "distance": {90.0, 91.0},
    "arc distance": {90.1, 91.1}, "feed mode": {93.0, 94.0, 95.0}, "units": {20.0, 21.0},
    "cutter radius compensation": {40.0, 41.0, 42.0, 41.1, 42.1},
    "tool length offset": {43.0, 43.1, 49.0}, "retract": {98.0, 99.0},
    "coordinate system": {54.0, 55.0, 56.0, 57.0, 58.0, 59.0, 59.1, 59.2, 59.3},
    "path control": {61.0, 61.1, 64.0}, "spindle mode": {96.0, 97.0},
    "non-modal": {4.0, 10.0, 28.0, 28.1, 30.0, 30.1, 52.0, 53.0, 92.0, 92.1, 92.2, 92.3},
}
_G_KNOWN = set().union(*_G_GROUPS.values())
#: Non-modal codes whose line's axis words are theirs, not a move (LinuxCNC's
#: "mode_zero_covets_axes").
_AXIS_CODES = {10.0, 28.0, 30.0, 52.0, 92.0}
_G_REFUSED = {41.0: "cutter radius compensation changes the path", 42.0: "cutter radius "
              "compensation changes the path", 41.1: "cutter radius compensation changes the "
              "path", 42.1: "cutter radius compensation changes the path",
              93.0: "inverse-time feed is not simulated", 95.0: "feed per revolution is not "
              "simulated", 96.0: "constant surface speed is not simulated"}
#: G codes LinuxCNC runs that woodcam does not simulate: (what it is, the fix).
_G_NOT_SIMULATED = {
    **dict.fromkeys((5.0, 5.1, 5.2, 5.3), ("a spline or NURBS", "post-process with lines and "
                                            "arcs (G1/G2/G3)")),
    **dict.fromkeys((7.0, 8.0), ("a lathe diameter/radius mode", "post-process for a mill")),
    **dict.fromkeys((33.0, 33.1, 76.0), ("threading or rigid tapping, spindle-synchronised",
                                         "remove the threading; drill the hole with G81")),
    **dict.fromkeys((38.2, 38.3, 38.4, 38.5), ("a probing move", "probe before the job and "
                                               "remove the probing lines")),
    **dict.fromkeys((74.0, 84.0), ("a tapping cycle", "drill the hole with G81 (woodcam "
                                   "does not simulate tapping)")),
    **dict.fromkeys((87.0, 88.0), ("a boring cycle with a spindle stop",
                                   "use G85 or G89 (bore, feed out), which woodcam simulates")),
    43.2: ("an added tool length offset", "remove it (woodcam measures tools from the tip)"),
}
_M_KNOWN = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 30, 48, 49, 50, 51, 52, 53, 60, 61}
#: M codes LinuxCNC runs that woodcam does not simulate: (what it is, the fix). The modal state
#: M70-M73 keep (units, distance mode, plane, feed, spindle ...) would have to be restored
#: exactly as LinuxCNC does, or a part is cut in the wrong units or mode without a word.
_M_NOT_SIMULATED = {
    70: ("saves the modal state for an M72", "write the modes M72 restores (G20/G21, G90/G91, "
         "G17-G19, F, S ...) where it restores them, and remove M70 and M72"),
    71: ("invalidates the modal state M70 or M73 saved", "remove it with the M70/M72 or M73 it "
         "belongs to, writing their modes out"),
    72: ("restores the modal state M70 saved", "write the modes it restores (G20/G21, G90/G91, "
         "G17-G19, F, S ...) in its place, and remove M70 and M72"),
    73: ("saves the modal state, restored when the subroutine returns", "write the modes the "
         "caller needs (G20/G21, G90/G91, G17-G19, F, S ...) after the call, and remove M73"),
}
#: LinuxCNC's M modal groups: two M codes of one group on a line are refused ("Two m codes used
#: from same modal group"; grbl refuses its M0/M1/M2/M30, M3-M5 and M7-M9 pairs the same way,
#: error 21), as are more than :data:`MAX_M_PER_LINE` M codes on one line.
_M_GROUPS = {"stopping": {0, 1, 2, 30, 60, 99}, "spindle": {3, 4, 5, 19}, "tool change": {6, 61},
             "coolant": {7, 8, 9}, "override": set(range(48, 54)),
             "input/output": set(range(62, 69)), "user-defined": set(range(100, 200))}
#: LinuxCNC refuses a fifth M code on one line ("Too many m codes on line").
MAX_M_PER_LINE = 4
#: M codes that switch I/O or call user programs: read, not simulated, warned about.
_M_WARN = {19: "spindle orientation: the spindle stands until M3/M4", 62: "digital output", 63: "digital output",
           64: "digital output", 65: "digital output", 66: "wait on input",
           67: "analog output", 68: "analog output", **{k: "user-defined M code (runs a "
                                                         "program of the machine)"
                                                         for k in range(100, 200)}}
_CS = (54.0, 55.0, 56.0, 57.0, 58.0, 59.0, 59.1, 59.2, 59.3)
_PLANES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}  # (first, second, normal) axes
_CENTRE = {17: "ij", 18: "ki", 19: "jk"}


#: The controller each dialect stands for, as a message names it ("post for ...").
_CONTROLLER = {"linuxcnc": "LinuxCNC", "grbl": "grbl", "fanuc": "a Fanuc control"}
#: What each dialect's controller does with G70/G71, the old units codes.
_OLD_UNITS_READ = {
    "linuxcnc": "LinuxCNC reads it as a lathe cycle and refuses it ('G7x.x requires a Q word')",
    "grbl": "grbl refuses it (error:20, an unsupported G code)",
    "fanuc": "a Fanuc control reads the units as G20/G21 (G70/G71 are its lathe cycles)"}


def _shifted(move, d):
    """A canonical move moved by ``d`` (3,) mm: its end and, for an arc, its centre (which holds
    the plane's first and second axes)."""
    kind, line, end, centre, rot, plane, *rest = move
    end = tuple(e + o for e, o in zip(end, d))
    if centre is not None:
        a1, a2, _ = _PLANES[plane]
        centre = (centre[0] + d[a1], centre[1] + d[a2])
    return (kind, line, end, centre, rot, plane, *rest)


def line_list(lines: list[int], most: int = 12) -> str:
    """``[7, 17, 30]`` -> ``"7, 17, 30"``; beyond ``most`` lines, ``"... (40 lines)"``."""
    text = ", ".join(map(str, lines[:most]))
    return text + (f", ... ({len(lines)} lines)" if len(lines) > most else "")


def _cs_base(n: int) -> int:
    """First parameter of coordinate system ``n`` (1 = G54 ... 9 = G59.3): 5221 + 20 (n-1)."""
    return 5221 + 20 * (n - 1)


#: LinuxCNC's read-only numbered parameters (assigning one is refused there, "Parameter is
#: readonly"): #5400 the loaded tool, #5401-#5413 its tool-table entry, #5420-#5428 the position.
_READ_ONLY_NUM = frozenset(range(5400, 5414)) | frozenset(range(5420, 5429))
#: What #5401-#5413 hold: the loaded tool's entry in the machine's tool table (the values as
#: the table has them, in the machine's units, whatever G20/G21; LinuxCNC 2.9's rs274 -t).
_TOOL_ENTRY = {**{5401 + i: f"{a} offset" for i, a in enumerate("XYZABCUVW")},
               5410: "diameter", 5411: "front angle", 5412: "back angle", 5413: "orientation"}
#: The tool changer's fault flag and reason, set by the machine (0 here: no fault). LinuxCNC
#: lets a program assign them but reads the machine's value over the assignment.
_TOOLCHANGER_FAULT = {5600: "flag", 5601: "reason"}
#: Parameters that hold what the machine measured when the program ran: a G38 probe result
#: (#5061-#5070) or an M66 input (#5399); woodcam simulates neither, so reading one the program
#: did not assign is refused (LinuxCNC would read the last probe's or input's value).
_MEASURED = {**{k: "a G38 probe result" for k in range(5061, 5071)}, 5399: "an M66 input"}

#: What the last return or endsub left (LinuxCNC: read-only, 0 before any; the interpreter
#: keeps them among its globals).
_RETURNED = ("_value", "_value_returned")


def _unknown(what: str) -> str:
    return f"{what}, which woodcam cannot know"


#: LinuxCNC 2.9's predefined named parameters (its manual's "Predefined Named Parameters", the
#: table of interp_namedparams.cc) but #<_value> and #<_value_returned> (:data:`_RETURNED`):
#: read-only (assigning one is refused, as LinuxCNC does), all defined (``EXISTS[]`` gives 1).
#: Each reads woodcam's state (program units, as LinuxCNC), or is a ``str``: what the machine
#: knows and woodcam does not, the reason reading it is refused. The constant ones follow from
#: what woodcam refuses (G41/G42, G93, G95, G96, G7/G8, remapped codes).
_PREDEFINED: dict[str, Callable[[Interpreter], float] | str] = {
    "_vmajor": lambda s: 2.9,  # the language woodcam reads is LinuxCNC 2.9's
    "_vminor": _unknown("the patch release of the machine's LinuxCNC (0.x of 2.9.x)"),
    # 1: running under LinuxCNC's task, as on the machine that cuts the part (its preview, the
    # oracle's gcode module, reads 0): a program's "o1 if [#<_task> eq 0]" branch, which posts
    # use to skip probing and tool measuring in the preview, is the machine's, not the cut's
    "_task": lambda s: 1.0,
    "_call_level": lambda s: float(len(s._frames)),  # o-word calls and M98 subprograms
    "_remap_level": lambda s: 0.0,
    "_line": lambda s: float(s.line_no),
    "_motion_mode": lambda s: 800.0 if s.motion is None else round(s.motion * 10),
    "_plane": lambda s: s.plane * 10.0,
    "_ccomp": lambda s: 400.0,
    "_metric": lambda s: float(not s.inch),
    "_imperial": lambda s: float(s.inch),
    "_absolute": lambda s: float(not s.incremental),
    "_incremental": lambda s: float(s.incremental),
    "_inverse_time": lambda s: 0.0,
    "_units_per_minute": lambda s: 1.0,
    "_units_per_rev": lambda s: 0.0,
    "_coord_system": lambda s: round(_CS[s.cs - 1] * 10.0),  # G54 540 ... G59.1 591 ... 593
    "_tool_offset": lambda s: float(any(s.tlo)),
    "_retract_r_plane": lambda s: float(not s.retract_old_z),  # G99
    "_retract_old_z": lambda s: float(s.retract_old_z),  # G98
    "_spindle_rpm_mode": lambda s: 1.0,
    "_spindle_css_mode": lambda s: 0.0,
    "_ijk_absolute_mode": lambda s: float(not s.arc_incremental),
    "_lathe_diameter_mode": lambda s: 0.0,
    "_lathe_radius_mode": lambda s: 1.0,
    "_spindle_on": lambda s: float(s.spindle_on),
    "_spindle_cw": lambda s: float(s.spindle_on and s.spindle_cw),
    "_mist": lambda s: float(s.coolant["mist"]),
    "_flood": lambda s: float(s.coolant["flood"]),
    "_speed_override": lambda s: float(s.overrides["speed"]),
    "_feed_override": lambda s: float(s.overrides["feed"]),
    "_adaptive_feed": lambda s: float(s.overrides["adaptive"]),
    "_feed_hold": lambda s: float(s.overrides["hold"]),
    "_feed": lambda s: s.feed / s.scale,
    "_rpm": lambda s: s.spindle,
    "_current_tool": lambda s: float(s.tool),
    "_selected_tool": lambda s: float(s.selected),
    "_current_pocket": _unknown("the tool changer pocket of the loaded tool, from the "
                                "machine's tool table"),
    "_selected_pocket": _unknown("the tool changer pocket of the selected tool, from the "
                                 "machine's tool table"),
    **{f"_{a}": (lambda s, i=i: s.to_program(s.pos)[i]) for i, a in enumerate("xyz")},
    **{f"_{a}": (lambda s: 0.0) for a in "abcuvw"},  # woodcam has no such axes
}


_DIGITS = re.compile(r"[0-9]+")


def tool_entry_in_message(k: int, ref: str, kind: str, tool: int,
                          diameters: dict[int, float]) -> tuple[float | str, str | None]:
    """``#k`` (5401-5413, written ``ref``) in a ``kind`` (DEBUG/PRINT) text with tool ``tool``
    loaded: ``(what the text shows, the warning or None)``. LinuxCNC shows the loaded tool's
    entry in the machine's tool table: 0 with no tool loaded (T0, before the first M6:
    LinuxCNC's T0 is no tool, its entry empty, as ``rs274 -t TABLE`` shows), the diameter
    ``#5410`` where the user's tools (``diameters``, mm by number) have the loaded tool, else
    a text that says what LinuxCNC would show there, with a warning (``#5403?`` said neither
    what nor why). Woodcam's interpreter and ``--interpreter linuxcnc`` (:mod:`.linuxcnc`)
    both show and warn by it."""
    if tool == 0:
        return 0.0, None
    if k == 5410 and tool in diameters:
        return float(diameters[tool]), None
    what = f"T{tool}'s {_TOOL_ENTRY[k]}"
    shown = f"[{ref}: {what}, from the machine's tool table]"
    give = (f"; give the tool (--tools TABLE, --tool {tool}=SPEC; read_gcode's "
            "tool_diameters_mm) to see its diameter" if k == 5410 else "")
    return shown, (f"({kind},...) shows {ref}, {what} in the machine's tool table, which "
                   f"woodcam does not know: the message says '{shown}' where LinuxCNC shows "
                   f"the table's value{give}")


def add_line_warning(warnings: list, warned: dict, line: int, msg: str, pass_id: object) -> None:
    """Append ``(line, msg)`` to ``warnings`` once per line and text: a line in a loop or a
    subroutine runs again and again; a line warned again in another pass (``pass_id``)
    counts its passes in the one warning. ``warned`` keeps ``(line, msg) -> [index, passes,
    last pass]`` between calls (:meth:`Interpreter.warn`, ``--interpreter linuxcnc``)."""
    key = (line, msg)
    seen = warned.get(key)
    if seen is None:
        warned[key] = [len(warnings), 1, pass_id]
        warnings.append((line, msg))
    elif seen[2] != pass_id:
        seen[1:] = [seen[1] + 1, pass_id]
        warnings[seen[0]] = (line, f"{msg} (warned once; the line ran {seen[1]} times)")


def _lf(value: float | None) -> str:
    """A parameter's value in a DEBUG/PRINT text as LinuxCNC 2.9 writes it: C's ``%lf`` of the
    value (within its 1e-4 'equal' of 0: 0, never -0.000000), ``######`` for none or for
    text of 30 characters or more (its buffer)."""
    if value is None:
        return "######"
    text = f"{0.0 if abs(value) < 1e-4 else value:f}"
    return text if len(text) < 30 else "######"


class _Unread(Exception):
    """A parameter without a value read by a sub definition's ``endsub [...]``: LinuxCNC reads
    that expression as it passes over the definition and takes undefined memory for it."""


class _Line:
    """A source line after comments are taken out: lowercase, no whitespace (LinuxCNC's
    normalisation), the 1-based line number and the messages of its comments. ``okey``: the
    O-word command (``sub``, ``call``, ...), ``"o"`` for a bare ``O1000`` program number (a
    Fanuc-style subprogram's label), ``"m98"``/``"m99"`` for a subprogram call or return."""

    __slots__ = ("text", "no", "msg", "okey", "olabel", "oexpr", "late")

    def __init__(self, text, no, msg):
        self.text, self.no, self.msg = text, no, msg
        self.okey = self.olabel = self.oexpr = None
        # 'N', '/', 'M98', 'M99' or the O word: that start-of-line word came after a comment;
        # 'M98.0'/'M99.0' (as written): a call or return with a decimal point
        self.late = None


def _after_comment(raw: str, text: str) -> str | None:
    """``'N'`` or ``'/'`` when the line's leading block delete or line number (``text``, the
    normalised line) follows a comment in ``raw`` (``(c) N5 G1``, ``(c) /G1``): LinuxCNC reads
    both only as the line's first characters ("Bad character 'n' used"), else ``None``."""
    if "(" not in raw or text[:1] not in ("n", "/"):
        return None
    head = raw.lstrip()
    if text[0] == "/":
        if not head.startswith("/"):
            return "/"
        head, text = head[1:].lstrip(), text[1:]
    return "N" if text[:1] == "n" and head[:1] not in ("n", "N") else None


_N_PREFIX = re.compile(r"/?(?:n\d+(?:\.\d+)?)?")


def _first_word_after_comment(raw: str, text: str) -> bool:
    """Whether the first word after the line number of ``text`` (the normalised line) follows a
    comment in ``raw`` (``(c) M98 P100``, ``N5 (c) O100``): LinuxCNC reads an O word, M98 or
    M99 as one only there ("Bad character 'o' used", "Unknown m code used: M98")."""
    if "(" not in raw:
        return False
    before = raw[:raw.index("(")].translate(_BLANKS).lower()  # the normalised text before it
    return len(before) <= _N_PREFIX.match(text).end()


def _late_rule(word: str) -> tuple[str, str]:
    """``(rule, fix)`` of the error for a start-of-line ``word`` (``_Line.late``) reached after
    a comment."""
    if word in ("N", "/"):
        what = "a line number (N word)" if word == "N" else "a block delete '/'"
        return (f"{what} after a comment: LinuxCNC reads it only as the first word of a line "
                "('Bad character' there)", f"move the comment after the {word} or remove the "
                f"{word}")
    if word[:4] in ("M98.", "M99."):
        said = "Bad character '.' used" if word[:3] == "M98" else "Unexpected character " \
               "after O-word"
        return (f"{word}: LinuxCNC reads a subprogram call or return only as M98 or M99 "
                f"without a decimal point ('{said}')", f"write {word[:3]}")
    if word == "M98":
        what = "a subprogram call M98 after a comment: LinuxCNC reads M98 as a call only as " \
               "the first word of its line ('Unknown m code used: M98' there)"
    elif word == "M99":
        what = "a subprogram return M99 after a comment: LinuxCNC reads M99 as a return only " \
               "as the first word of its line (it stops there)"
    else:
        label = "" if " " in word else "; M98 does not find such a label"
        what = f"an O word ({word}) after a comment: LinuxCNC reads O words only as the first " \
               f"word of a line ('Bad character' there{label})"
    return what, f"move the comment after the {word.split()[0]}"


#: What LinuxCNC skips between words: space and tab (and the carriage return of a CRLF line
#: end). Python's str.split() also skips form feed, vertical tab, no-break space, ..., which
#: LinuxCNC refuses ("Bad character '\014' used").
_BLANKS = str.maketrans("", "", " \t\r")
#: C's isspace() less the line end: what LinuxCNC strips off the end of a line, and the blanks it
#: skips inside a #<name> of a DEBUG/PRINT text (isspace's "\n" never occurs inside a line).
_C_SPACE = " \t\r\v\f"


def source_lines(text: str) -> list[str]:
    """The lines of program ``text`` as LinuxCNC and editors number them: broken at ``\\n``
    (``\\r\\n`` too) only. ``str.splitlines`` also breaks at ``\\r`` alone, form feed, vertical
    tab, ``\\x1c``-``\\x1e``, ``\\x85`` and U+2028/9, which shifted every later line number (a
    file with ``\\r\\r\\n`` line ends doubled them) and cut ``G1 X5\\r Y5`` into two moves. A
    file with ``\\r`` alone for its line ends (classic Mac OS) is broken at ``\\r``: LinuxCNC
    reads it as one line and refuses it; :class:`Interpreter` warns."""
    if "\n" not in text and "\r" in text:
        lines = text.split("\r")
    else:
        lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    return lines


#: LinuxCNC's longest line in bytes (its LINELEN, 255, less the line end and the NUL)
MAX_LINE = 252


def _too_long_lines(lines: list[str], text: str) -> dict[int, int]:
    """``{line number: bytes}`` of the source ``lines`` (of ``text``, :func:`source_lines`)
    LinuxCNC refuses as 'Command too long': over :data:`MAX_LINE` bytes, a ``\\r`` of a
    Windows line end counted; a last line without a line end may be one longer (LinuxCNC's
    fgets reads 254 bytes, the line end among them). None for a file of ``\\r`` line ends,
    which LinuxCNC reads as one line (:class:`Interpreter` warns of it)."""
    if "\n" not in text:
        return {} if "\r" in text or len(text.encode()) <= MAX_LINE + 1 else {1: len(text.encode())}
    last = len(lines) - 1
    ended = text.endswith("\n")
    return {i + 1: b for i, raw in enumerate(lines) if len(raw) * 4 > MAX_LINE
            for b in [len(raw.encode())] if b > MAX_LINE + (i == last and not ended)}


def nul_byte_error(lines: list[str]) -> GcodeError | None:
    """The refusal of the first of a program's source ``lines`` (:func:`source_lines`) where a
    NUL byte (``\\x00``) hides words, or ``None``. LinuxCNC (rs274, its AXIS preview) reads a
    line as a C string, only up to its first NUL, and drops the rest without a word:
    ``G1 X2\\x00 Y3 F100`` runs as ``G1 X2`` (refused for its zero feed, or run with the last
    one). Where only NULs and blanks follow (a file's zero padding, a line ending in NULs)
    nothing is lost and woodcam reads the line up to the NUL too (:func:`nul_cut`); where
    more follows, both of woodcam's interpreters refuse the program, naming the line, before
    running anything (such a NUL is a damaged file)."""
    for no, raw in enumerate(lines, start=1):
        col = raw.find("\x00") + 1
        if not col:
            continue
        rest = raw[col:].replace("\x00", "").strip(" \t\r")
        if not rest:
            continue
        return GcodeError(no, "NUL", f"a NUL byte (character {col} of the line, after "
                          f"{raw[:col - 1][-30:]!r}): LinuxCNC reads a line only up to a NUL "
                          f"and drops the rest, here {rest[:40]!r}, without a word; a NUL in "
                          "G-code is a damaged file (a copy cut short) or not text",
                          "remove the NUL byte and check the line is whole, or export the "
                          "program again")
    return None


def blank_program(lines: list[str]) -> bool:
    """Whether source ``lines`` (:func:`source_lines` cut at NULs, :func:`nul_cut`) hold only C
    blanks (``isspace``, form feed and vertical tab too), or none: rs274 opening such a file
    looks past the blank lines for an opening '%' and meets the end ('File ended with no
    percent sign', ``NO_PERCENT``, not ``NO_END``), as ``rs274 -g`` says of '', '\\n\\n',
    '\\t\\n' or '\\f\\n' (LinuxCNC 2.9)."""
    return all(not ln.strip(_C_SPACE + "\n") for ln in lines)


def nul_cut(lines: list[str]) -> list[str]:
    """Source ``lines`` as LinuxCNC reads them: each up to its first NUL byte (after
    :func:`nul_byte_error` found none that hides words, only NULs and blanks are cut)."""
    return [raw[:raw.index("\x00")] if "\x00" in raw else raw for raw in lines]


def split_comments(raw: str, no: int) -> tuple[str, list[tuple[str, str]]]:
    """Source line ``raw`` (1-based number ``no``) -> ``(text, messages)``: the text outside
    comments, lowercase, without whitespace, and its message comment as ``[(kind, text)]``
    (none or one): ``("msg", message)`` of ``(MSG, ...)``, ``("debug", text)`` of
    ``(DEBUG, ...)``, ``("print", text)`` of ``(PRINT, ...)`` and ``("abort", text)`` of
    ``(ABORT, ...)`` (LinuxCNC stops the program there with that text), whose text names parameters
    the interpreter puts the values of when the line runs (:meth:`Interpreter._expand`). LinuxCNC
    keeps only a line's last ``( )`` comment (a ``;`` comment is none): ``(MSG,a) (note)`` says
    nothing, ``(note) (MSG,b)`` says ``b``.
    Raises :class:`GcodeError` for an unclosed, nested or unopened comment."""
    if "(" not in raw and ")" not in raw and ";" not in raw:  # most lines: no comment
        return raw.translate(_BLANKS).lower(), []
    msgs = []
    out = []
    i = 0
    while i < len(raw):
        c = raw[i]
        if c == ";":
            break
        if c == "(":
            j = raw.find(")", i + 1)
            if j < 0:
                raise GcodeError(no, raw[i:], "unclosed comment", "close it with ')'")
            body = raw[i + 1:j]
            if "(" in body:
                raise GcodeError(no, raw[i:j + 1], "nested comment", "remove the inner '('")
            # the keyword as LinuxCNC reads it: after leading blanks, any case, the comma next
            head = body.lstrip()
            low = head[:6].lower()
            if low.startswith("msg,"):
                msgs = [("msg", head[4:].strip())]
            elif low.startswith(("debug,", "print,", "abort,")):
                msgs = [(low[:5], head[6:])]
            else:
                msgs = []
            i = j + 1
            continue
        if c == ")":
            raise GcodeError(no, ")", "')' without '('", "remove it")
        out.append(c)
        i += 1
    # LinuxCNC drops blanks and case outside comments, inside #<names> too
    return "".join(out).translate(_BLANKS).lower(), msgs


class Interpreter:
    """Runs one program; see the module docstring. ``run()`` returns ``(moves, warnings)``."""

    def __init__(self, text: str, *, dialect: Dialect = "linuxcnc", start_mm=(0.0, 0.0, 0.0),
                 params: dict[int, float] | None = None, max_blocks: int = MAX_BLOCKS,
                 max_moves: int = MAX_MOVES, machine_zero_mm=(0.0, 0.0, 0.0),
                 tool_diameters_mm: dict[int, float] | None = None):
        if dialect not in DIALECTS:
            raise WoodcamError(f"dialect must be one of {DIALECTS}, got {dialect!r}")
        self.dialect = dialect
        self.max_blocks, self.max_moves = int(max_blocks), int(max_moves)
        self.src = source_lines(text)
        self._nul = nul_byte_error(self.src)  # refused by run(), as every other fault
        self.src = nul_cut(self.src)
        self._too_long = _too_long_lines(self.src, text) if dialect == "linuxcnc" else {}
        # LinuxCNC takes every C blank (isspace: also form feed and vertical tab) off a line's
        # end before it reads it; inside the line they are 'Bad character' (woodcam refused
        # 'G0 X1\f', which rs274 runs)
        self.src = [ln.rstrip(_C_SPACE) if ln[-1:] in _C_SPACE and ("\f" in ln or "\v" in ln)
                    else ln for ln in self.src]
        # machine origin in the G-code frame (mm), None: not known (module docstring)
        self.mzero = None if machine_zero_mm is None else [float(v) for v in machine_zero_mm]
        shift = self.mzero or [0.0, 0.0, 0.0]
        self.start_z = float(start_mm[2])  # the retract height of an unplaced G53 Z
        self.pos = [float(v) - m for v, m in zip(start_mm, shift)]  # machine frame, mm
        self.p: dict[int, float] = {}
        for k in range(5161, 5164):
            self.p[k] = self.pos[k - 5161]
        for k in range(5181, 5184):
            self.p[k] = self.pos[k - 5181]
        for i in range(3):  # G54 offset: the G-code zero in machine coordinates
            self.p[5221 + i] = -shift[i]
        self.p[5220] = 1.0
        self.p[5599] = 1.0  # LinuxCNC's (DEBUG,...) output flag, on by default
        if params:
            # the machine-state ones are the interpreter's own (the loaded tool, its table
            # entry, the position, no tool-changer fault): a supplied value would be ignored,
            # so it is refused, as a program assigning one is; a probe result or input
            # (#5061-#5070, #5399) is the program's to read, and taken
            fixed = sorted(int(k) for k in params if int(k) in _READ_ONLY_NUM | set(_TOOLCHANGER_FAULT))
            if fixed:
                raise WoodcamError(f"params: #{fixed[0]} is the machine's state, which the "
                                   "interpreter keeps itself (#5400 the loaded tool, #5401-#5413 "
                                   "its tool table entry, #5420-#5428 the position, #5600/#5601 "
                                   f"no tool-changer fault); got params {fixed}; leave them out "
                                   "(start_mm gives the start position)")
            self.p.update({int(k): float(v) for k, v in params.items()})
        self.globals: dict[str, float] = {}
        self.locals: dict[str, float] = {}
        self._defining = False  # reading a definition's endsub value: see _returned
        self._value_unknown: str | None = None  # why #<_value> holds what LinuxCNC cannot know
        self.moves: list = []
        self.warnings: list[tuple[int, str]] = []
        if dialect == "linuxcnc" and "\r" in text and "\n" not in text and len(self.src) > 1:
            self.warnings.append((1, "the lines end in CR alone (classic Mac OS): woodcam reads "
                                  "them as lines, LinuxCNC reads the file as one line and "
                                  "refuses it; convert the line ends to LF or CRLF"))
        self.messages: list[tuple[int, str]] = []
        # the user's tools by number (mm): what a DEBUG/PRINT shows for #5410, the tool
        # table's diameter of the loaded tool (a program's expression still may not read it:
        # the machine's own table may differ)
        self.tool_diameters_mm = dict(tool_diameters_mm or {})
        # (PRINT,...) texts: LinuxCNC writes them to its standard output (the terminal it was
        # started from, rs274's stdout), not to the operator's screen as MSG and DEBUG
        self.printed: list[tuple[int, str]] = []
        # modal state
        self.inch = False
        self.incremental = False
        self.arc_incremental = True
        self.plane = 17
        # LinuxCNC starts in G80 (axis words alone are refused until a G0/G1/...); grbl and
        # Fanuc's controls start in G0 (Fanuc: parameter 3402 bit 0 clear, the default)
        self.motion: float | None = 0.0 if dialect != "linuxcnc" else None
        self.motion_cancelled = False  # a G80 has run (the refusal names it, or the start)
        self.retract_old_z = False  # LinuxCNC starts in G99 (retract to R)
        # mm/min: LinuxCNC (and grbl) convert F when it is read, so a later G20/G21 keeps the
        # physical feed (on a "G20 F10" line F is read first: 10 mm/min)
        self.feed = 0.0
        self.spindle = 0.0
        self.spindle_on = False
        self.spindle_cw = True  # M3 (False: M4), read while the spindle turns
        # M7/M8/M9 and M48-M53: read, no effect on the cut (#<_mist>, #<_feed_hold> ... read
        # them; LinuxCNC starts with both overrides and feed hold enabled, adaptive feed off)
        self.coolant = {"mist": False, "flood": False}
        self.overrides = {"speed": True, "feed": True, "adaptive": False, "hold": True}
        self.tool = 0
        self.selected = 0
        # a T word read and no M6 since: its tool is not the loaded one (M61 loads another
        # without touching the selection, as LinuxCNC)
        self._t_pending = False
        self.cs = int(self.p[5220])
        self.g5x = [self.p.get(_cs_base(self.cs) + i, 0.0) for i in range(3)]
        self.g92 = [self.p.get(5211 + i, 0.0) for i in range(3)] if self.p.get(5210) else [0.0] * 3
        self.tlo = [0.0, 0.0, 0.0]  # the active tool length offset (G43.1), mm
        self.cycle_il: float | None = None
        self.cyc = {"r": math.nan, "z": math.nan, "q": math.nan, "p": 0.0, "l": 1}
        self.motion_before = self.motion  # the motion mode before the line being run
        self.ended = False
        self.known = [False, False, False]
        self._warned_start = False
        self._t_warned: set[int] = set()
        # a warning by (line, text) -> [its index in warnings, passes, the last pass]: a
        # line in a loop or a subroutine runs on every pass, warned once (warn)
        self._warned: dict[tuple[int, str], list[int]] = {}
        self._warn_calls = 0
        self._message_pass = 0  # counts the DEBUG/PRINT texts put together (_expand)
        self._g53_unplaced: dict[str, list[int]] = {"z": [], "xy": []}  # lines, machine zero unknown
        self._frames: list[tuple] = []  # the active calls while run() runs
        self.line_no = 0
        self._opened_with_percent = False  # a '%' line first: LinuxCNC wants the closing one

    # -- helpers ----------------------------------------------------------------------------
    def err(self, word, rule, fix):
        return GcodeError(self.line_no, word, rule, fix)

    def _not_simulated(self, word, what_fix):
        """The error of a code LinuxCNC runs and woodcam refuses on purpose
        (:data:`_G_NOT_SIMULATED`, :data:`_M_NOT_SIMULATED` give ``(what it does, the fix)``)."""
        what, fix = what_fix
        # (LinuxCNC runs them all; a Fanuc control or grbl may not: their dialects say no more)
        runs = " (LinuxCNC runs it)" if self.dialect == "linuxcnc" else ""
        return self.err(word, f"{word} ({what}) is not simulated by woodcam{runs}", fix)

    def warn(self, msg: str, pass_id: int | None = None) -> None:
        """Warn ``msg`` once per line and text: a line in a loop or a subroutine runs again
        and again (a 500-pass while loop around ``M62 P1`` gave 500 identical warnings); a
        line warned again counts its passes in the one warning. ``pass_id`` (a DEBUG/PRINT
        text, :meth:`_warn_message`) makes a value read twice in one text one pass."""
        if pass_id is None:
            self._warn_calls += 1
            pass_id = -self._warn_calls  # (apart from the message passes, which count up)
        add_line_warning(self.warnings, self._warned, self.line_no, msg, pass_id)

    def _warn_message(self, msg: str) -> None:
        """Warn ``msg`` about a DEBUG/PRINT text once per line (its messages stay one a pass,
        as LinuxCNC shows them), a value read twice in one text once."""
        self.warn(msg, self._message_pass)

    @property
    def scale(self):
        return MM_PER_INCH if self.inch else 1.0

    def to_machine(self, prog):
        """Program (work) coordinates in program units -> machine frame mm (LinuxCNC: work +
        G92 + G5x)."""
        s = self.scale
        return [v * s + o + g for v, o, g in zip(prog, self.g5x, self.g92)]

    def to_program(self, mach):
        s = self.scale
        return [(v - o - g) / s for v, o, g in zip(mach, self.g5x, self.g92)]

    def emit(self, kind, end, centre=None, rotation=0):
        if len(self.moves) >= self.max_moves:
            raise self.err("program", f"more than {self.max_moves} moves (woodcam's memory "
                           "guard)", "split the program or raise max_moves")
        if kind == TRAVERSE or kind == FEED:
            if list(end) == self.pos:
                return  # zero-length: nothing to simulate (LinuxCNC emits some)
        if kind != TRAVERSE and not self._warned_start and not all(self.known):
            self._warned_start = True
            miss = "".join(a for a, k in zip("XYZ", self.known) if not k).upper()
            x, y, z = (v + m for v, m in zip(self.pos, self.mzero or (0, 0, 0)))  # G-code frame
            self.warn(f"the first cut starts before the program set {miss}: it starts from "
                      f"the start position {say_length((x, y, z), 'g', form='X{} Y{} Z{}')} (--start)")
        if (kind != TRAVERSE and self._t_pending and self.selected != self.tool
                and self.selected not in self._t_warned):
            self._t_warned.add(self.selected)
            self.warn(f"T{self.selected} was selected without M6: the cut goes on with the "
                      f"loaded tool T{self.tool}, as the controller does")
        feed = self.feed
        # the main-program line it ran under: the outermost active call's, else its own
        ran = self._frames[0][5] if self._frames else self.line_no
        self.moves.append((kind, self.line_no, tuple(end), centre, rotation, self.plane, feed,
                           self.spindle if self.spindle_on else 0.0, self.tool, self.inch, ran))
        self.pos = list(end)

    # -- parameters -------------------------------------------------------------------------
    def get_num(self, n: float, word: str) -> float:
        k = self._param_index(n, word)
        if 5400 <= k <= 5601:
            if k == 5400:
                return float(self.tool)
            if 5420 <= k <= 5422:  # as #<_x> #<_y> #<_z>: program units and frame
                return self.to_program(self.pos)[k - 5420]
            if 5423 <= k <= 5428 or k in _TOOLCHANGER_FAULT:  # A-W; no tool-changer faults
                return 0.0
            if 5401 <= k <= 5413:
                raise self.err(word, f"#{k} is the loaded tool's offset, diameter, angle or "
                               "orientation in the machine's tool table (#5401-#5413), which "
                               "woodcam does not know (its tools are measured from the tip)",
                               "put the value in a parameter of the program's own, e.g. "
                               "#<dia> = 6")
        if k in _MEASURED and k not in self.p:
            if self._defining:
                raise _Unread(word)
            raise self.err(word, f"#{k} holds {_MEASURED[k]} from the machine, which woodcam "
                           "does not simulate, and the program did not assign it",
                           f"assign #{k} before reading it")
        return self.p.get(k, 0.0)

    def _param_index(self, n, word):
        k = round(n)
        if abs(n - k) > 1e-4 or not 1 <= k <= 5601:
            raise self.err(word, f"parameter number {n:g} out of range (1-5601, integer)",
                           "use #1 ... #5601")
        return k

    def get_named(self, name, word):
        known = _PREDEFINED.get(name)
        if known is not None:
            if isinstance(known, str):
                raise self.err(word, f"#<{name}> is LinuxCNC's {known}",
                               f"replace #<{name}> by the value the machine would read, or "
                               "by a parameter of the program's own")
            return known(self)
        if name == "_value" and self._value_unknown:
            raise self.err(word, self._value_unknown, "call the subroutine before reading "
                           "#<_value>")
        d = self.globals if name.startswith("_") else self.locals
        if name in d:
            return d[name]
        if name in _RETURNED:
            return 0.0
        if self._defining:
            raise _Unread(word)
        if name.startswith(("_ini[", "_hal[")):
            what = "INI file value" if name.startswith("_ini[") else "HAL pin or signal"
            raise self.err(word, f"#<{name}> reads the machine's {what} (LinuxCNC with "
                           "[RS274NGC]FEATURES 4 or 8; without, it is not defined there "
                           "either), which woodcam cannot know", f"replace #<{name}> by the "
                           "value, or by a parameter the program assigns")
        raise self.err(word, f"named parameter #<{name}> not defined",
                       "assign it before reading it")

    # -- expression reader ------------------------------------------------------------------
    # Works on the normalised line text ``s`` with an index; returns (value, next index).
    def value(self, s: str, i: int):
        # a depth bound: 400 nested brackets (or 3000 unary minus signs) hit Python's recursion
        # limit, a RecursionError traceback; no real program nests a tenth as deep
        self._depth = getattr(self, "_depth", 0) + 1
        try:
            if self._depth > MAX_EXPR_DEPTH:
                raise self.err(s[:20], f"expression nested deeper than {MAX_EXPR_DEPTH} levels",
                               "simplify it")
            return self._value(s, i)
        finally:
            self._depth -= 1

    def _value(self, s: str, i: int):
        if i >= len(s):
            raise self.err(s, "a value is missing at the end of the line", "complete the word")
        c = s[i]
        if c == "[":
            v, i = self.expr(s, i + 1)
            if i >= len(s) or s[i] != "]":
                raise self.err(s, "expression without closing ']'", "close it")
            return v, i + 1
        if c == "#":
            return self.param_value(s, i)
        if c.isdigit() or c == "." or (c in "+-" and i + 1 < len(s)
                                       and (s[i + 1].isdigit() or s[i + 1] == ".")):
            m = _NUM.match(s, i)
            if not m:
                raise self.err(s[i:i + 8], "bad number", "write digits with one '.'")
            v = float(m.group(0))
            if not math.isfinite(v):
                raise self.err(m.group(0)[:20] + "...", "number out of range",
                               "use a number below 1e308")
            return v, m.end()
        if c == "-":
            v, i = self.value(s, i + 1)
            return -v, i
        if c == "+":
            return self.value(s, i + 1)
        if c.isalpha():
            for f in _FUNCS:
                if s.startswith(f, i):
                    return self.func(f, s, i + len(f))
        raise self.err(s[i:i + 10], "bad value (a number, #parameter, [expression] or "
                       "function)", "fix the word")

    def param_value(self, s, i):
        if s.startswith("#<", i):
            m = _NAME.match(s, i + 1)
            if not m:
                raise self.err(s[i:], "named parameter without '>'", "write #<name>")
            return self.get_named(m.group(1), s[i:m.end()]), m.end()
        n, j = self.value(s, i + 1)
        return self.get_num(n, s[i:j]), j

    def func(self, f, s, i):
        if i >= len(s) or s[i] != "[":
            raise self.err(f, f"function {f} without '[' argument", f"write {f}[...]")
        if f == "exists":
            m = re.compile(r"\[#<([^>]*)>\]").match(s, i)
            if not m:
                raise self.err(s[i:], "exists needs [#<name>]", "write exists[#<name>]")
            name = m.group(1)
            d = self.globals if name.startswith("_") else self.locals
            # the predefined ones exist, those woodcam cannot read too (LinuxCNC defines them)
            return float(name in d or name in _PREDEFINED or name in _RETURNED), m.end()
        a, i = self.value(s, i)
        w = f"{f}[{a:g}]"
        if f == "atan":
            if not s.startswith("/[", i):
                raise self.err(w, "atan needs two arguments, atan[y]/[x]", "write atan[y]/[x]")
            b, i = self.value(s, i + 1)
            return math.degrees(math.atan2(a, b)), i
        try:
            if f == "sin":
                v = math.sin(math.radians(a))
            elif f == "cos":
                v = math.cos(math.radians(a))
            elif f == "tan":
                v = math.tan(math.radians(a))
            elif f == "asin":
                if abs(a) > 1:
                    raise self.err(w, "asin argument outside [-1, 1]", "fix the argument")
                v = math.degrees(math.asin(a))
            elif f == "acos":
                if abs(a) > 1:
                    raise self.err(w, "acos argument outside [-1, 1]", "fix the argument")
                v = math.degrees(math.acos(a))
            elif f == "sqrt":
                if a < 0:
                    raise self.err(w, "square root of a negative number", "fix the argument")
                v = math.sqrt(a)
            elif f == "abs":
                v = abs(a)
            elif f == "round":  # half away from zero, as LinuxCNC
                v = math.copysign(math.floor(abs(a) + 0.5), a)
            elif f == "fix":
                v = float(math.floor(a))
            elif f == "fup":
                v = float(math.ceil(a))
            elif f == "exp":
                v = math.exp(a)
            else:  # ln
                if a <= 0:
                    raise self.err(w, "logarithm of a number <= 0", "fix the argument")
                v = math.log(a)
        except OverflowError:
            v = math.inf
        if not math.isfinite(v):
            raise self.err(w, "result out of range", "use smaller numbers")
        return v, i

    def expr(self, s, i):
        """Inside ``[`` ... up to (not past) the closing ``]``: precedence climbing."""
        return self._binary(s, i, 0)

    def _binary(self, s, i, min_prec):
        left, i = self.value(s, i)
        while i < len(s) and s[i] != "]":
            for op, prec in _BINOPS:
                if s.startswith(op, i):
                    break
            else:
                raise self.err(s[i:i + 6], "unknown operator in expression",
                               "use ** * / mod + - eq ne gt ge lt le and or xor")
            if prec <= min_prec:
                return left, i
            # left-associative: the right operand binds only tighter operators
            right, i = self._binary(s, i + len(op), prec)
            left = self._apply(op, left, right)
        return left, i

    def _apply(self, op, a, b):
        w = f"{a:g} {op} {b:g}"
        try:
            if op == "**":
                if a < 0 and b != math.floor(b):
                    raise self.err(w, "negative number to a non-integer power", "fix it")
                if a == 0 and b < 0:
                    raise self.err(w, "zero to a negative power", "fix it")
                v = math.pow(a, b)
            elif op == "*":
                v = a * b
            elif op == "/":
                if b == 0:
                    raise self.err(w, "division by zero", "fix the divisor")
                v = a / b
            elif op == "mod":
                if b == 0:
                    raise self.err(w, "mod by zero", "fix the divisor")
                v = math.fmod(a, b)
                if v < 0:
                    v += abs(b)
            elif op == "+":
                v = a + b
            elif op == "-":
                v = a - b
            elif op == "eq":
                v = float(abs(a - b) < _EQ_TOL)
            elif op == "ne":
                v = float(abs(a - b) >= _EQ_TOL)
            elif op == "gt":
                v = float(a > b)
            elif op == "ge":
                v = float(a >= b)
            elif op == "lt":
                v = float(a < b)
            elif op == "le":
                v = float(a <= b)
            elif op == "and":
                v = float(a != 0 and b != 0)
            elif op == "or":
                v = float(a != 0 or b != 0)
            else:
                v = float((a != 0) != (b != 0))
        except OverflowError:
            v = math.inf
        if not math.isfinite(v):
            raise self.err(w, "result out of range", "use smaller numbers")
        return v

    # -- program structure ------------------------------------------------------------------
    def _prepare(self):
        """Normalise every line and match the O-word structure once (LinuxCNC matches by label:
        ``o100 if`` ... ``o100 endif``)."""
        if self._nul is not None:
            raise self._nul
        lines: list[_Line] = []
        percent = False
        closing = None  # index of the line of the closing '%'
        first = True
        grbl = self.dialect == "grbl"
        grbl_percent: list[int] = []  # grbl: the '%' lines dropped
        self._late_olabels: dict[str, int] = {}  # O label after a comment -> its first line
        self._late_subs: dict[str, int] = {}  # 'oN sub' label after a comment -> its first line
        # line index -> (key, label, rest) of each o-word after a comment, as it would be read
        late_owords: dict[int, tuple[str, str, str]] = {}
        for no, raw in enumerate(self.src, start=1):
            self.line_no = no
            text, msg = split_comments(raw, no)
            # LinuxCNC reads '%' only as a line of its own (blanks around it, no comment): the
            # first non-blank line opens a %-delimited program and the next such line ends it;
            # any other '%' is refused when it is reached ("Bad character '%' used": the
            # moves after it never run). grbl's firmware has no '%' at all: it answers every
            # '%' line with error:1 ("Expected command letter") and moves nothing; its senders
            # drop those lines (Universal G-code Sender strips every '%') or report the error
            # and stream on (grbl's own stream.py), so the moves after any '%' run: woodcam
            # drops them all, and warns about one inside the program (not the delimiters a
            # post writes first and last), where a sender that stops on errors stops the job.
            if grbl:
                if text == "%":
                    grbl_percent.append(no)
                    continue
            else:
                # blanks as LinuxCNC's (_BLANKS): str.strip() also took a form feed, vertical
                # tab or no-break space, which LinuxCNC refuses ("Bad character"), for one
                stripped = raw.strip(" \t\r")
                bare = stripped == "%"
                if first and stripped:
                    first = False
                    if bare:
                        percent = self._opened_with_percent = True
                        continue
                if bare and percent:
                    closing = len(lines)
                    lines.append(_Line("%", no, msg))
                    break
            ln = _Line(text, no, msg)
            late = False  # the O word, M98 or M99 that may start the line follows a comment
            if not grbl:
                ln.late = _after_comment(raw, text)
                late = _first_word_after_comment(raw, text)
            body = text[1:] if text.startswith("/") else text
            m = _OWORD.match(body) if "o" in body else None
            if m:
                label = m.group(1).strip("<>")
                label = str(int(label)) if label.isdigit() else label
                key, rest = m.group(2), m.group(3)
                for k in sorted(_OKEYS, key=len, reverse=True):
                    if key.startswith(k):
                        rest = key[len(k):] + rest
                        key = k
                        break
                else:
                    raise GcodeError(no, text, f"unknown O-word command {key!r}",
                                   "use sub, endsub, call, return, if, elseif, else, endif, "
                                   "while, endwhile, do, repeat, endrepeat, break, continue")
                if self.dialect == "grbl":
                    raise GcodeError(no, text, "grbl has no O-word subroutines or loops",
                                   "use --dialect linuxcnc")
                if late:  # LinuxCNC reads no O word there: a plain line, "Bad character"
                    # when it runs, skipped as text inside a definition or a branch not taken
                    # (so it opens or closes nothing): refused when reached
                    ln.late = ln.late or f"o{label} {key}"
                    if key == "sub":  # why a call finds no oN sub (a commented call defines none)
                        self._late_subs.setdefault(label, no)
                    # said for a program that runs (one that reaches the line is refused): the
                    # line was skipped, an else or endwhile with the lines it was to frame
                    self.warnings.append((no, f"'o{label} {key}' follows a comment, so it is "
                                          "no O word (LinuxCNC reads one only as the first word "
                                          "of its line) and was skipped as text; move the "
                                          f"comment after the o{label}"))
                    late_owords[len(lines)] = (key, label, rest)
                else:
                    ln.okey, ln.olabel, ln.oexpr = key, label, rest
            elif m is None and "o" in body and _ONUMBER.match(body):
                if grbl:
                    raise GcodeError(no, text, "grbl has no O words (an O1234 program number is "
                                   "LinuxCNC's or Fanuc's)", "remove it or pass --dialect "
                                   "linuxcnc")
                # O1234: a program number, which LinuxCNC 2.9 runs through; it labels the
                # Fanuc-style subprogram that M98 P1234 calls
                label = str(int(body[body.index("o") + 1:]))
                if late:  # refused when reached; M98 does not find it
                    ln.late = ln.late or f"O{label}"
                    self._late_olabels.setdefault(label, no)
                else:
                    ln.okey, ln.olabel = "o", label
            elif not grbl and "m9" in body:
                mm = _M98_M99.match(body)
                if mm and late:  # M98 refused when reached, M99 when it would return
                    ln.late = ln.late or "M" + mm.group(1)
                elif mm:  # M98/M99 first on the line: a call or return (grbl: refused as M codes)
                    ln.okey, ln.oexpr = "m" + mm.group(1), mm.group(2)
                elif not late and (md := _M98_M99_DECIMAL.match(body)):
                    ln.late = ln.late or md.group(1).upper()
            lines.append(ln)
        self.lines = lines
        self.closing = closing
        # no line but blanks: rs274 looks past them for the opening '%' and meets the end
        # (one rule with --interpreter linuxcnc's, whose parse skips that look: blank_program)
        self._blank_file = not grbl and blank_program(self.src)
        words = [ln.no for ln in lines if ln.text]
        inside = [no for no in grbl_percent if words and words[0] < no < words[-1]]
        if inside:
            self.warnings.append((inside[0], f"'%' on line(s) {line_list(inside)} inside the "
                                  "program: grbl's firmware answers it with error:1 (Expected "
                                  "command letter); senders drop the line or report the error "
                                  "and go on, so woodcam skipped it, but a sender that stops on "
                                  "errors stops the job there; keep '%' to the first and last "
                                  "line"))
        try:
            self._match_structure(lines)
            if late_owords and self.refused_at:
                # an O word after a comment (which LinuxCNC reads as none) may be why the labels
                # do not match: refused now, at that line, as a mismatch is (the first found)
                raise next(iter(self.refused_at.values()))
        except GcodeError as e:
            blame = self._late_blame(lines, late_owords, e)
            if blame is None:
                raise
            # the o-word after a comment is why the labels do not match (LinuxCNC does not
            # read it as one): refused there
            first = lines[blame]
            rule, fix = _late_rule(first.late)
            raise GcodeError(first.no, first.late, f"{rule}; without it the O words do not "
                             f"match (line {e.line}: {e.rule})", fix) from None

    def _late_blame(self, lines: list[_Line], late_owords: dict[int, tuple[str, str, str]],
                    e: GcodeError) -> int | None:
        """The index in ``lines`` of the o-word after a comment (``late_owords``: index -> its
        key, label, rest) to refuse for the O-word structure error ``e``, or None when none
        explains it: the first with the label of the line ``e`` names (an unrelated commented
        o5 call took the blame for an unclosed o7 while); when none carries it but the structure
        matches with them read as O words, the first that opens or closes one (not a call or
        return, which match nothing)."""
        if not late_owords:
            return None
        trial = []
        for i, ln in enumerate(lines):  # copies: matching marks a do's while as "dowhile"
            t = _Line(ln.text, ln.no, ln.msg)
            t.okey, t.olabel, t.oexpr = late_owords.get(i, (ln.okey, ln.olabel, ln.oexpr))
            t.okey = "while" if t.okey == "dowhile" else t.okey
            trial.append(t)
        label = next((ln.olabel for ln in lines if ln.no == e.line and ln.olabel is not None), None)
        same = next((i for i, (_, lab, _) in sorted(late_owords.items()) if lab == label), None)
        try:
            self._match_structure(trial)  # the program is refused either way
        except GcodeError:
            return same
        if same is not None:
            return same
        return next((i for i, (key, _, _) in sorted(late_owords.items())
                     if key not in ("call", "return")), min(late_owords))

    def _match_structure(self, lines):
        """Match the O-word structure of the normalised ``lines`` (the parts of _prepare)."""
        self.match: dict[int, int] = {}   # opener index -> closer index (and back)
        self.branches: dict[int, list[int]] = {}  # if index -> [elseif/else..., endif]
        self.owner: dict[int, int] = {}  # break/continue/elseif/else/return index -> opener
        self.subs: dict[str, int] = {}  # sub label -> its first definition's index
        self.sub_defs: dict[str, list[int]] = {}  # sub label -> every definition's index
        self._breaks: dict[int, list[int]] = {}  # loop opener index -> its break lines' indices
        # if/while/do/repeat index -> the indices of those nested in it with its label
        self._inner_same: dict[int, list[int]] = {}
        # line index -> the error LinuxCNC raises when the program reaches that line (an endsub
        # or return outside every definition, an endif, else, break ... of a label no if or loop
        # opens), or passes over the definition there (one holding another sub's): it runs the
        # lines before, and a line never reached is never refused
        self.refused_at: dict[int, GcodeError] = {}
        stack: list[tuple[str, str, int]] = []
        self.olabels: dict[str, list[int]] = {}  # bare O label -> its line indices
        # the labels an if or loop opens anywhere: a closer, else, break or continue of another
        # label LinuxCNC refuses only when it reaches it ('undefined O-word label')
        opened = {ln.olabel for ln in lines if ln.okey in ("if", "while", "do", "repeat")}

        def undefined(idx: int, ln: _Line, rule: str) -> None:
            self.refused_at[idx] = GcodeError(
                ln.no, f"o{ln.olabel} {ln.okey}", f"{rule}: no if or loop has the label o{ln.olabel} "
                "(LinuxCNC: 'undefined O-word label', when the program reaches it)",
                "match the O-word labels")
            ln.okey = "refused"

        for idx, ln in enumerate(lines):
            k = ln.okey
            if k is None:
                continue
            self.line_no = ln.no
            if k in ("o", "m99"):
                sub = next((s for s in stack if s[0] == "sub"), None)
                if sub is not None:  # LinuxCNC refuses both when it passes the definition
                    word = f"O{ln.olabel}" if k == "o" else "M99"
                    raise GcodeError(ln.no, word, f"{word} inside the o{sub[1]} sub "
                                     "definition (LinuxCNC: 'Nested subroutine definition' / "
                                     "'Found M99 instead of O endsub'): Fanuc-style subprograms "
                                     "(O1000 ... M99) and o-word subroutines (o100 sub ... o100 "
                                     "endsub) do not mix", f"end o{sub[1]} with o{sub[1]} endsub "
                                     "and put the O1000 subprogram after it")
                if k == "o":
                    self.olabels.setdefault(ln.olabel, []).append(idx)
                continue
            if k == "m98":
                continue
            if k == "while" and stack and stack[-1][0] == "do" and stack[-1][1] == ln.olabel:
                _, _, op = stack.pop()
                self.match[op], self.match[idx] = idx, op
                ln.okey = "dowhile"
            elif k in ("sub", "if", "while", "do", "repeat"):
                if k != "sub":
                    for s in stack:
                        if s[1] == ln.olabel and s[0] != "sub":
                            self._inner_same.setdefault(s[2], []).append(idx)
                if k == "sub":
                    outer = next((s for s in stack if s[0] == "sub"), None)
                    if outer is not None:
                        # LinuxCNC refuses it as it passes over the outer definition ('Nested
                        # subroutine definition'); a call of the outer sub runs through this
                        # line, and an endsub of this label there returns from that call
                        # (below): so the line is no O word, and the outer sub is refused when
                        # passed over, at this line
                        self.refused_at.setdefault(outer[2], GcodeError(
                            ln.no, f"o{ln.olabel} sub", f"subroutine o{ln.olabel} defined inside "
                            f"the o{outer[1]} sub of line {lines[outer[2]].no}: LinuxCNC refuses "
                            "it when the program passes over that definition ('Nested "
                            "subroutine definition')", "move it out"))
                        ln.okey = "nested"
                        continue
                    self.subs.setdefault(ln.olabel, idx)
                    self.sub_defs.setdefault(ln.olabel, []).append(idx)
                stack.append((k, ln.olabel, idx))
                if k == "if":
                    self.branches[idx] = []
            elif k == "endsub" and any(s[0] == "sub" and s[1] != ln.olabel for s in stack):
                # inside another sub's definition (o101 sub ... o100 endsub): LinuxCNC passes
                # over a definition to the endsub with its label, and when a call reaches this
                # line it returns as from 'o101 return' (checked: the lines after it never run)
                sub = next(s for s in reversed(stack) if s[0] == "sub")
                ln.okey = "return"
                self.owner[idx] = sub[2]
                self.warnings.append((ln.no, f"o{ln.olabel} endsub inside the o{sub[1]} sub "
                                      f"of line {lines[sub[2]].no}: LinuxCNC reads it as "
                                      f"o{sub[1]}'s return (a call of o{sub[1]} ends here, "
                                      f"its lines after it never run), and so does woodcam; "
                                      f"write o{sub[1]} return (or fix the label)"))
            elif k in ("endsub", "return") and not any(s[0] == "sub" for s in stack):
                # outside every definition: LinuxCNC refuses it only when it reaches it ('not in
                # a subroutine definition'): after M2, or in a branch not taken, it never does
                self.refused_at[idx] = GcodeError(
                    ln.no, f"o{ln.olabel} {k}", f"{k} outside a subroutine definition (no "
                    f"o{ln.olabel} sub is open here; LinuxCNC: 'not in a subroutine definition')",
                    "match the O-word labels, or use M2 to end the program" if k == "return"
                    else "match the O-word labels")
                ln.okey = "refused"
            elif k in ("endif", "endwhile", "endrepeat", "elseif", "else", "break", "continue") \
                    and ln.olabel not in opened:
                undefined(idx, ln, {"endif": "endif without an if", "endwhile": "endwhile without a while",
                                    "endrepeat": "endrepeat without a repeat", "elseif": "elseif without an if",
                                    "else": "else without an if"}.get(k, f"{k} outside a loop"))
            elif k in ("endsub", "endif", "endwhile", "endrepeat"):
                want = {"endsub": "sub", "endif": "if", "endwhile": "while",
                        "endrepeat": "repeat"}[k]
                if not stack or stack[-1][0] != want or stack[-1][1] != ln.olabel:
                    raise GcodeError(ln.no, f"o{ln.olabel} {k}", f"{k} without a matching "
                                   f"o{ln.olabel} {want}", "match the O-word labels")
                _, _, op = stack.pop()
                self.match[op], self.match[idx] = idx, op
                if k == "endif":
                    self.branches[op].append(idx)
            elif k in ("elseif", "else"):
                if not stack or stack[-1][0] != "if" or stack[-1][1] != ln.olabel:
                    raise GcodeError(ln.no, f"o{ln.olabel} {k}", f"{k} without o{ln.olabel} if",
                                   "match the O-word labels")
                self.branches[stack[-1][2]].append(idx)
                self.owner[idx] = stack[-1][2]
            elif k in ("break", "continue"):
                loop = next((s for s in reversed(stack) if s[1] == ln.olabel
                             and s[0] in ("while", "do", "repeat")), None)
                if loop is None:
                    raise GcodeError(ln.no, f"o{ln.olabel} {k}", f"{k} outside an o{ln.olabel} "
                                   "loop", "match the O-word labels")
                self.owner[idx] = loop[2]
                if k == "break":
                    self._breaks.setdefault(loop[2], []).append(idx)
            elif k == "return":  # (outside every definition: refused when reached, above)
                sub = next(s for s in reversed(stack) if s[0] == "sub")
                self.owner[idx] = sub[2]
        if stack:
            k, label, idx = stack[-1]
            sub = next((s for s in stack if s[0] == "sub"), None)
            if sub is not None:  # LinuxCNC passes over a definition to its endsub: to the end
                k, label, idx = sub
                unclosed = GcodeError(lines[idx].no, f"o{label} sub", f"o{label} sub is never "
                                      f"closed by an o{label} endsub: LinuxCNC reads the rest of "
                                      "the file as its definition, runs none of it and stops at "
                                      "the end ('File ended with no percent sign or program "
                                      f"end')", f"end the definition with o{label} endsub")
                if stack[0] is not sub:  # an if or loop open before it: never matched
                    raise unclosed
                # refused when the program reaches it (or calls it): the lines before it run,
                # as in LinuxCNC (a sub after the program's M2 is never read)
                self.refused_at[idx] = unclosed
                return
            raise GcodeError(lines[idx].no, f"o{label} {k}", f"o{label} {k} is never closed",
                           "close it")

    def run(self):
        self._prepare()
        lines = self.lines
        # (return index, saved #1-#30 (None for M98), saved locals, sub index, the call's label
        # and line): one per active o-word call or M98 subprogram call
        frames: list[tuple] = []
        self._frames = frames
        self._m98_left: dict[int, int] = {}  # M98 L repeats left, by calling depth
        self._m98_target: dict[str, int] = {}  # O label -> line index, once an M98 found it
        # sub label -> the index of the definition LinuxCNC has for it: the first one passed
        # over, or the one a call found searching forward (_sub_target)
        self._defined: dict[str, int] = {}
        # (scope, label) -> the index of the first if/while/do/repeat line reached with that
        # label; scope: the label of the subroutine or subprogram running it, None for the main
        # program (LinuxCNC keeps them by subroutine name, across calls: _label_reached)
        self._olabels_reached: dict[tuple[str | None, str], int] = {}
        repeat_left: dict[int, int] = {}
        stale_break: int | None = None  # line of a break out of a while loop, still "set"
        pc = 0
        blocks = 0
        n = len(lines)
        too_long = self._too_long
        while pc < n:
            ln = lines[pc]
            self.line_no = ln.no
            if too_long and ln.no in too_long:  # refused when reached (LinuxCNC reads it then)
                raise self.err(f"line {ln.no}", f"the line is {too_long[ln.no]} "
                               f"bytes long: LinuxCNC reads at most {MAX_LINE} before a line end "
                               f"({MAX_LINE + 1} on a last line without one) and refuses a "
                               "longer one ('Command too long'), stopping the program here",
                               "shorten it: split a long expression or comment over lines")
            blocks += 1
            if blocks > self.max_blocks:
                raise self.err("program", f"more than {self.max_blocks} lines executed (an "
                               "endless loop?)", "check the loop conditions")
            # refused when reached, as LinuxCNC (an uncalled sub's line is not); the main
            # program's M99 is an ordinary line there too (below)
            if ln.late and (not ln.late.startswith("M99") or frames):
                raise self.err(ln.late, *_late_rule(ln.late))
            k = ln.okey
            if k is None:
                if pc == self.closing:
                    self.ended = True
                    break
                # a line LinuxCNC runs as a block says its message; an O-word line, M98, M99
                # in a call and an O program number are read by its flow control, which
                # never looks at their comments
                if ln.text:
                    self.block(ln.text, ln.msg)
                    if self.ended:
                        break
                elif ln.msg:
                    self._say(ln.msg)
                pc += 1
                continue
            if k == "sub":
                if pc in self.refused_at:  # a sub defined inside it
                    raise self.refused_at[pc]
                if ln.oexpr:  # LinuxCNC reads the line as it passes over the definition (a call
                    # that finds the definition searching forward does not read it)
                    raise self.err(f"o{ln.olabel} sub{ln.oexpr}", "text after o"
                                   f"{ln.olabel} sub (LinuxCNC: 'Unexpected character after "
                                   "O-word'; a sub takes its arguments as #1, #2, ... from the "
                                   "call)", f"write o{ln.olabel} sub alone on its line")
                self._define_sub(pc, ln)
                # LinuxCNC reads the definition's returns and its endsub as it passes over the
                # body, in order (not its ifs or loops): #<_value> becomes the last value, 0
                # where the endsub has none, though no call ran, and a value it cannot compute
                # ('o100 return [1/0]') is refused on its line before any line after the body
                # runs (woodcam cut the moves up to a call and refused there)
                for i in range(pc + 1, self.match[pc]):
                    if lines[i].okey == "return" and self.owner.get(i) == pc:
                        self._returned(lines[i], definition=True)
                self._returned(lines[self.match[pc]], definition=True)
                pc = self.match[pc] + 1
            elif k == "refused":
                raise self.refused_at[pc]
            elif k == "nested":  # a sub line inside a definition, reached in a call: LinuxCNC
                pc += 1  # runs on through it (its definition refused when passed over: above)
            elif k == "o":  # a program number: run through it, as LinuxCNC and Fanuc (never
                # inside an o-word sub: _prepare refuses one in a definition)
                pc += 1
            elif k == "m98":
                pc = self._m98(pc, ln)
            elif k == "m99":
                if not frames:  # the main program's M99: an ordinary line (LinuxCNC's read_m)
                    self.block(ln.text, ln.msg)
                    if self.ended:
                        break
                    pc += 1
                    continue
                pc = self._m99(ln)
            elif k == "call":
                if len(frames) >= MAX_CALL_DEPTH:
                    raise self.err(f"o{ln.olabel} call", f"more than {MAX_CALL_DEPTH} nested "
                                   "subroutine calls (LinuxCNC's limit)", "reduce the nesting")
                if ln.olabel not in self.subs and ln.olabel in self._late_subs:
                    raise self.err(f"o{ln.olabel} call", f"the o{ln.olabel} on line "
                                   f"{self._late_subs[ln.olabel]} follows a comment: LinuxCNC "
                                   "reads an O word only as the first word of its line, so "
                                   f"there is no o{ln.olabel} sub ('EOF seeking o-word')",
                                   f"move the comment after the o{ln.olabel}")
                if ln.olabel not in self.subs:
                    raise self.err(f"o{ln.olabel} call", f"subroutine o{ln.olabel} is not "
                                   "defined in this file (woodcam reads one file; LinuxCNC "
                                   "would search its SUBROUTINE_PATH)",
                                   "define it in the program")
                target = self._sub_target(pc, ln)
                if target not in self.match:  # a definition never closed (_match_structure)
                    raise self.refused_at[target]
                args = self._call_args(ln.oexpr)
                saved = {i: self.p.get(i, 0.0) for i in range(1, 31)}
                frames.append((pc + 1, saved, self.locals, target, ln.olabel, ln.no))
                self.locals = {}
                for i in range(1, 31):
                    self.p[i] = args[i - 1] if i <= len(args) else 0.0
                pc = target + 1
            elif k in ("endsub", "return"):
                self._returned(ln)
                if not frames:  # a sub body reached without a call: LinuxCNC skips it
                    pc = (self.match[pc] if k == "endsub" else self.match[self.owner[pc]]) + 1
                    continue
                # the innermost call is this sub's: an M98 subprogram starts at an O label,
                # outside every definition (_prepare), and passes over a definition it meets
                ret, saved, loc, *_ = frames.pop()
                self.p.update(saved)
                self.locals = loc
                pc = ret
            elif k == "if":
                self._label_reached(pc, ln)
                target = self._if(pc)
                stop = self._skipping(pc, pc, target)
                pc = target if stop is None else stop
            elif k in ("elseif", "else"):  # reached the end of a taken branch
                target = self.branches[self.owner[pc]][-1]
                stop = self._skipping(self.owner[pc], pc, target)
                pc = target + 1 if stop is None else stop
            elif k == "endif":
                pc += 1
            elif k == "while":
                self._label_reached(pc, ln)
                v, _ = self._cond(ln)
                stop = self._skipping(pc, pc, self.match[pc]) if v == 0 else None
                if v == 0 and self._breaks.get(pc) and stop is None:
                    # LinuxCNC skips to the loop's end by its label and so runs the loop's own
                    # break on the way (a break it reads sets the flag a do loop reads below)
                    stale_break = lines[self._breaks[pc][0]].no
                pc = pc + 1 if v != 0 else self.match[pc] + 1 if stop is None else stop
            elif k == "endwhile":
                pc = self.match[pc]
            elif k == "do":
                self._label_reached(pc, ln)
                pc += 1
            elif k == "dowhile":
                other_do = self._label_reached(pc, ln)
                v, _ = self._cond(ln)
                if v != 0 and stale_break is None and other_do is not None:
                    raise self.err(f"o{ln.olabel} while", f"the o{ln.olabel} do loop of "
                                   f"line {lines[self.match[pc]].no} loops back here, and "
                                   f"LinuxCNC 2.9 goes back to the o{ln.olabel} do it reached "
                                   f"first, on line {lines[other_do].no}, and runs the lines "
                                   "from there again", "give each do loop its own label")
                if v != 0 and stale_break is not None:
                    # LinuxCNC 2.9 leaves the flag of a break out of a while loop set, and the
                    # next do loop's test reads it (and clears it): that loop ends here
                    self.warn(f"the o{ln.olabel} do loop ends after this pass though its "
                              f"condition holds: LinuxCNC 2.9 still carries the break of line "
                              f"{stale_break} (out of a while loop) and reads it here, and "
                              "woodcam does as LinuxCNC; write the do loop as a while loop, or "
                              "end the while loop by its condition instead of a break")
                    v = 0.0
                stale_break = None
                pc = self.match[pc] + 1 if v != 0 else pc + 1
            elif k == "repeat":
                self._label_reached(pc, ln)
                if pc not in repeat_left:
                    v, _ = self._cond(ln)
                    repeat_left[pc] = int(round(v))
                if repeat_left[pc] > 0:
                    repeat_left[pc] -= 1
                    pc += 1
                else:
                    del repeat_left[pc]
                    stop = self._skipping(pc, pc, self.match[pc])
                    pc = self.match[pc] + 1 if stop is None else stop
            elif k == "endrepeat":
                pc = self.match[pc]
            elif k in ("break", "continue") and lines[self.owner[pc]].okey == "repeat":
                raise self.err(f"o{ln.olabel} {k}", f"{k} in an o{ln.olabel} repeat loop: "
                               f"LinuxCNC leaves or restarts only while and do loops ('no "
                               f"matching while/do label')", f"write the loop as o{ln.olabel} "
                               f"while, or guard the rest of the body with an o-if")
            elif k == "break":  # (of a while or do loop: a repeat's is refused above)
                if lines[self.owner[pc]].okey == "while":
                    stale_break = ln.no
                stop = self._skipping(self.owner[pc], pc, self.match[self.owner[pc]])
                pc = self.match[self.owner[pc]] + 1 if stop is None else stop
            elif k == "continue":
                op = self.owner[pc]
                stop = self._skipping(op, pc, self.match[op])
                later = [i for i in self._breaks.get(op, []) if i > pc]
                if stop is not None:  # a do loop under the label: the program runs on there
                    pc = stop
                elif lines[op].okey == "while":
                    if later:  # LinuxCNC skips to the loop's end by its label and runs the
                        # loop's own break on the way: the loop goes on, the flag stays set
                        stale_break = lines[later[0]].no
                    pc = op
                elif later:  # a do loop: the break's flag ends it at its while line
                    self.warn(f"o{ln.olabel} continue on line {ln.no} ends the do loop: "
                              f"LinuxCNC skips to the next o{ln.olabel} line, the break on line "
                              f"{lines[later[0]].no}, and runs it; woodcam does as LinuxCNC")
                    pc = self.match[op] + 1
                else:
                    pc = self.match[op]
            else:  # pragma: no cover - _prepare only lets the keys above through
                raise self.err(k, "unknown O-word", "fix it")
        if not self.ended and frames and frames[-1][1] is None:
            self.warn(f"the file ends inside the subprogram O{frames[-1][4]} (called on line "
                      f"{frames[-1][5]}): no M99 returns from it and nothing ends the program "
                      "(LinuxCNC: 'File ended with no percent sign or program end')")
        elif not self.ended:
            if self.dialect == "linuxcnc":
                # the file's last line (1 of an empty file), the one rs274 quotes, not the last
                # run: a loop that ends the file ended on its own first line
                self.line_no = max(len(self.src), 1)
                said = NO_PERCENT if self._opened_with_percent or self._blank_file else NO_END
                self.warn(f"the file ends without M2, M30 or '%' (LinuxCNC stops here with "
                          f"'{said}')")
        self._warn_g53_unplaced()
        if self.mzero and any(self.mzero):
            self.moves = [_shifted(m, self.mzero) for m in self.moves]
        return self.moves, self.warnings

    def _label_reached(self, pc: int, ln: _Line) -> int | None:
        """LinuxCNC 2.9's check of an if, while, do or repeat line (index ``pc``) reached: it
        keeps the first line reached with each label, per subroutine (or subprogram, or the
        main program) and across its calls, and refuses another line with that label
        ('duplicate O-word label'), except a do line (it keeps the first) and a do loop's own
        while line. Returns, for a do loop's while line whose label an earlier, other do loop
        holds, that do's index (LinuxCNC loops back there), else None."""
        frames = self._frames
        key = (frames[-1][4] if frames else None, ln.olabel)
        first = self._olabels_reached.get(key)
        if first is None or first == pc:
            if first is None and ln.okey != "dowhile":
                self._olabels_reached[key] = pc
            return None
        k, seen = ln.okey, self.lines[first]
        if k == "do":
            return None
        if seen.okey == "do" and k == "dowhile":
            return None if first == self.match[pc] else first
        scope = ("the main program" if key[0] is None else f"subprogram O{key[0]}"
                 if frames[-1][1] is None else f"subroutine o{key[0]}")
        word = "while" if k == "dowhile" else k
        if seen.okey == "do" and k == "while":
            rule = (f"o{ln.olabel} labels the o{ln.olabel} do loop on line {seen.no} already: "
                    f"LinuxCNC 2.9 reads this o{ln.olabel} while as the end of that do loop "
                    "(it loops back there, or runs on into this loop's body)")
        else:
            rule = (f"o{ln.olabel} labels the o{ln.olabel} {seen.okey} on line {seen.no} "
                    f"already, in {scope}: LinuxCNC 2.9 refuses a label used by a second "
                    "if/while/do/repeat there when it is reached ('duplicate O-word label')")
        raise self.err(f"o{ln.olabel} {word}", rule, "give each if, while, do and repeat its "
                       "own label (a label may repeat only in different subroutines)")

    def _skipping(self, owner: int, frm: int, to: int) -> int | None:
        """The program skips from line index ``frm`` to ``to`` (exclusive) out of the if, loop
        or branch opened at index ``owner``: LinuxCNC skips to the next line with its label and
        reads every such line on the way, so an if/while/do/repeat nested in it with the same
        label is refused there though it is not run ('duplicate O-word label'). At a do it
        stops skipping and runs on into that loop (checked: its body is cut, then its while
        line is refused as a duplicate of the outer label, or, inside an outer do, the program
        runs on): the do's index is returned, where the program goes on, with a warning; else
        None. (A break of the loop skipped that LinuxCNC runs on the way sets the flag that
        ends a do loop at its while line: where that matters, the do's while has a true
        condition, which woodcam refuses as a second do loop under one label.)"""
        inner = self._inner_same.get(owner)
        i = next((j for j in inner if frm < j < to), None) if inner else None
        if i is None:
            return None
        ln, outer = self.lines[i], self.lines[owner]
        label = ln.olabel
        self.line_no = ln.no
        if ln.okey == "do":
            self.warn(f"the o{label} do on line {ln.no} lies inside the o{label} {outer.okey} "
                      f"of line {outer.no}, under the same label: LinuxCNC 2.9 skips to that "
                      f"{outer.okey}'s end by the label, stops at this do and runs on into "
                      "it (lines the program skips are cut), and woodcam does as LinuxCNC; "
                      "give each if, while, do and repeat its own label")
            return i
        why = "refuses it ('duplicate O-word label')"
        raise self.err(f"o{label} {ln.okey}", f"this o{label} {ln.okey} lies inside the "
                       f"o{label} {outer.okey} of line {outer.no}, under the same label: "
                       f"LinuxCNC 2.9 skips to that {outer.okey}'s end by the label, reads this "
                       f"line on the way and {why}", "give each if, while, do and repeat its "
                       "own label")

    def _define_sub(self, pc: int, ln: _Line) -> None:
        """The sub definition on line index ``pc`` is passed over: LinuxCNC 2.9 defines the
        subroutine there, and refuses a label it has defined before: by another definition
        ('redefining sub'), or by this one, found by an earlier call that searched forward to
        it or passed over before by a loop ('found in illegal location')."""
        label = ln.olabel
        first = self._defined.get(label)
        if first is None:
            self._defined[label] = pc
            return
        if first == pc:
            raise self.err(f"o{label} sub", f"the o{label} sub definition is reached a second "
                           "time (a call before it found it by searching the file forward, or a "
                           "loop passes over it again): LinuxCNC 2.9 refuses it here ('sub: "
                           f"o|{label}| found in illegal location')", f"define o{label} before "
                           "its first call and outside every loop, or after the program's M2")
        raise self.err(f"o{label} sub", f"subroutine o{label} is defined a second time (first "
                       f"on line {self.lines[first].no}): LinuxCNC 2.9 refuses the second "
                       "definition when it reaches it ('redefining sub'), and calls before it "
                       "run the first", "give one of the two subroutines another label")

    def _sub_target(self, pc: int, ln: _Line) -> int:
        """The index of the definition the ``oN call`` on line index ``pc`` runs, as LinuxCNC
        2.9 finds it: the one it has defined (passed over, or found by an earlier call), else
        the first definition after the call (it searches the file forward from there)."""
        label = ln.olabel
        target = self._defined.get(label)
        if target is None:
            target = next((i for i in self.sub_defs.get(label, ()) if i > pc), None)
            if target is None:
                where = line_list([self.lines[i].no for i in self.sub_defs[label]])
                raise self.err(f"o{label} call", f"the o{label} sub definition (line(s) {where}) "
                               "was never passed over before this call (it lies in a branch or "
                               "loop not run) and none follows the call: LinuxCNC searches the "
                               f"file forward for it ('EOF ... seeking o-word: o<{label}>')",
                               f"define o{label} before the main program, outside every if and "
                               "loop")
            self._defined[label] = target
        return target

    def _warn_g53_unplaced(self):
        """One warning per kind of G53 move placed without the machine zero, naming its lines."""
        fix = ("give where the machine zero lies in the G-code frame (--machine-zero X,Y,Z) to "
               "place them")
        for key, what in (("z", f"without the machine zero each G53 Z was taken as a retract "
                                f"to Z{say_length(self.start_z, 'g')} (the --start height, or the tool's Z "
                                "if higher)"),
                          ("xy", "without the machine zero their X/Y were taken with the "
                                 "machine zero at G-code zero: the machine goes elsewhere")):
            lines = self._g53_unplaced[key]
            if lines:
                self.warnings.append((lines[0], f"G53 (machine coordinates) on line(s) "
                                      f"{line_list(lines)}: {what}; {fix}"))

    def _m98(self, pc, ln):
        """``M98 P<n> [L<count>]`` on line index ``pc``: call the subprogram labelled ``O<n>``
        as LinuxCNC 2.9 does (module docstring); returns the next line index."""
        w = self._m98_words(ln.oexpr)
        if "p" not in w:
            raise self.err("M98", "M98 without P (the number of the subprogram to call; "
                           "LinuxCNC: 'Found m98 code with no P-word')",
                           "write M98 P1000 to call the subprogram labelled O1000")
        p = w["p"]
        n = math.floor(p)
        if p - n > 0.9999:  # LinuxCNC's integer reading
            n += 1
        elif p - n > 0.0001:
            raise self.err(f"P{p:g}", "M98 P must be a whole number (an O program number)",
                           "fix P")
        reps = None
        if "l" in w:
            if w["l"] < 0 or abs(w["l"] - round(w["l"])) > 0.0001:
                raise self.err(f"L{w['l']:g}", "M98 L (how many times to call) must be a whole "
                               "number >= 0", "fix L")
            reps = int(round(w["l"]))
        label = str(n)
        if (self.dialect == "fanuc" and reps is None and n > 9999
                and label not in self.olabels and str(n % 10000) in self.olabels):
            # Fanuc's own form: M98 P51002 calls O1002 five times (count, then 4 digits)
            reps, label = n // 10000, str(n % 10000)
        depth = len(self._frames)
        ret = pc + 1
        if reps is not None:
            if reps == 0 and depth not in self._m98_left:
                if self.dialect == "linuxcnc":
                    self.warn(f"M98 P{label} L0 calls nothing; LinuxCNC 2.9 still opens a call "
                              "level there that it never closes (named parameters set before "
                              "it read as undefined after it, and a later M99 returns to it): "
                              "woodcam simulated the call skipped; remove the line")
                return pc + 1
            left = self._m98_left.get(depth, reps) - 1
            if left > 0:  # LinuxCNC runs the M98 line again after the M99 (P read again)
                self._m98_left[depth] = left
                ret = pc
            else:
                self._m98_left.pop(depth, None)
        target = self._m98_target.get(label)
        if target is None:
            target = self._find_olabel(pc, label)
            self._m98_target[label] = target
        if depth >= MAX_CALL_DEPTH:
            chain = " > ".join(f"O{f[4]}" if f[1] is None else f"o{f[4]}" for f in self._frames)
            raise self.err(f"M98 P{label}", f"more than {MAX_CALL_DEPTH} nested subroutine calls "
                           f"(LinuxCNC's limit; the calls open: {chain}): a subprogram that calls "
                           "itself never returns", "reduce the nesting or end the recursion")
        self._frames.append((ret, None, self.locals, target, label, ln.no))
        self.locals = {}  # named locals are the call's own (#1-#30 are shared: not saved)
        return target + 1

    def _find_olabel(self, pc, label):
        """Line index of the ``O<label>`` line an ``M98 P<label>`` on line index ``pc`` calls:
        LinuxCNC searches forward from its first call; Fanuc keeps each program apart, so the
        fanuc dialect takes the one ``O<label>`` line wherever it is."""
        where = self.olabels.get(label, [])
        if not where:
            if label in self.subs:
                raise self.err(f"M98 P{label}", f"o{label} is an o-word subroutine (o{label} "
                               "sub), which M98 does not call (LinuxCNC: 'O.... sub' subroutine "
                               "must be called with 'O.... call')", f"write o{label} call")
            if label in self._late_olabels:
                raise self.err(f"M98 P{label}", f"the O{label} on line "
                               f"{self._late_olabels[label]} follows a comment: LinuxCNC reads "
                               "an O label only as the first word of its line ('EOF seeking "
                               "o-word')", f"move the comment after the O{label}")
            raise self.err(f"M98 P{label}", f"no O{label} line in this file (woodcam reads one "
                           f"file; a control would look for program O{label} in its memory)",
                           f"add the subprogram (O{label} ... M99) after the main program's "
                           "M30, or fix P")
        if self.dialect != "linuxcnc":
            if len(where) > 1:
                raise self.err(f"M98 P{label}", f"O{label} labels lines "
                               f"{line_list([self.lines[i].no for i in where])}: which one M98 "
                               "calls is ambiguous", "renumber one of them")
            return where[0]
        after = [i for i in where if i > pc]
        if not after:
            raise self.err(f"M98 P{label}", f"O{label} is on line {self.lines[where[0]].no}, "
                           "before the M98 that first calls it: LinuxCNC searches the file "
                           "forward from there ('EOF seeking o-word')",
                           f"move the subprogram O{label} ... M99 after the main program's M30")
        return after[0]

    def _m98_words(self, s):
        """The words of an M98 line after ``M98`` (normalised text ``s``): ``{'p': .., 'l': ..}``."""
        w: dict[str, float] = {}
        i = 0
        while i < len(s):
            c = s[i]
            if c not in "pl":
                raise self.err(f"M98 {s[i:].upper()}", "an M98 line holds P (the subprogram) "
                               "and L (how many times) only: woodcam reads no other word on it "
                               "(LinuxCNC skips them without a word)",
                               "put the other words on a line of their own")
            if c in w:
                raise self.err(c.upper(), f"word {c.upper()} twice on one line", "keep one")
            w[c], i = self.value(s, i + 1)
        return w

    def _m99(self, ln):
        """``M99`` first on its line inside an M98 call: return (the main program's M99 is an
        ordinary line, :meth:`execute`); returns the next line index."""
        if ln.oexpr:
            raise self.err(f"M99 {ln.oexpr.upper()}", "nothing may follow an M99 that returns "
                           "from a subprogram (LinuxCNC: 'Unexpected character after O-word'; "
                           "Fanuc's M99 P<n>, a return to line N<n>, is not read)",
                           "write M99 alone on its line")
        ret, _, loc, *_ = self._frames.pop()
        self.locals = loc
        self.globals["_value"] = self.globals["_value_returned"] = 0.0  # LinuxCNC: no value
        self._value_unknown = None  # a definition's unreadable endsub value is replaced
        return ret

    def _cond(self, ln, definition: bool = False):
        """The value of the ``[...]`` of O-word line ``ln`` and where it ends in ``ln.oexpr``.
        ``definition``: ``ln`` is the endsub of a definition passed over, which LinuxCNC reads
        only up to its value: text after it (or text instead of one: no value, ``(None, 0)``)
        is refused only when a call returns there."""
        s = ln.oexpr
        what = "value" if ln.okey in ("return", "endsub") else "condition"
        if definition and not s.startswith("["):
            return None, 0
        if what == "value" and not s.startswith("["):
            raise self.err(f"o{ln.olabel} {ln.okey}{s}", f"text after o{ln.olabel} {ln.okey} "
                           "(LinuxCNC: 'Unexpected character after O-word')", f"remove it, or "
                           f"give the value in [ ]: o{ln.olabel} {ln.okey} [...]")
        if not s.startswith("["):
            raise self.err(f"o{ln.olabel} {ln.okey}{s}", f"{ln.okey} needs a [{what}]",
                           f"write o{ln.olabel} {ln.okey} [...]")
        v, i = self.value(s, 0)
        if s[i:] and not definition:
            said = " (LinuxCNC: 'Unexpected character after O-word')" if what == "value" else ""
            raise self.err(s[i:], f"text after the {what}{said}", "remove it")
        return v, i

    def _returned(self, ln, definition: bool = False) -> None:
        """Set ``#<_value>`` and ``#<_value_returned>`` as LinuxCNC's ``return`` or ``endsub``
        line ``ln`` does: ``o1 return [v]`` and ``o1 endsub [v]`` alike give ``v`` and 1,
        either without a value 0 and 0. ``definition``: ``ln`` is read as the program passes
        over its definition (a return in it, then its endsub), where a parameter without a
        value leaves ``#<_value>`` unknown (refused when read) instead of refusing the program,
        and text after the value is left for a call to refuse."""
        v = None
        self._value_unknown = None
        if ln.oexpr:
            self.line_no, self._defining = ln.no, definition
            try:
                v = self._cond(ln, definition)[0]
            except _Unread as e:
                v = 0.0
                self._value_unknown = (
                    f"o{ln.olabel} {ln.okey} on line {ln.no} set #<_value> where its subroutine "
                    f"is defined, before any call, and there {e} has no value (LinuxCNC reads "
                    "undefined memory for it)")
            finally:
                self._defining = False
        self.globals["_value"] = 0.0 if v is None else v
        self.globals["_value_returned"] = float(v is not None)

    def _call_args(self, s):
        args = []
        i = 0
        while i < len(s):
            if s[i] != "[":
                raise self.err(s[i:], "subroutine arguments must each be in [ ]", "write [1] [2]")
            v, i = self.value(s, i)
            args.append(v)
        if len(args) > 30:
            raise self.err(s[:20], "more than 30 subroutine arguments", "pass at most 30")
        return args

    def _if(self, pc):
        chain = [pc] + self.branches[pc]
        for b in chain[:-1]:
            ln = self.lines[b]
            if ln.okey == "else":
                return b + 1
            self.line_no = ln.no  # (an error in an elseif's condition names its line)
            v, _ = self._cond(ln)
            if v != 0:
                return b + 1
        return chain[-1] + 1

    # -- one block --------------------------------------------------------------------------
    def block(self, s: str, notes=()):
        """Run the normalised line ``s``; ``notes``: its message comment (split_comments),
        said after the line's parameter assignments and before its codes, as LinuxCNC does
        (``#1=5 (DEBUG,#1)`` says 5, ``G0 X5 (DEBUG,#<_x>)`` the X before the move)."""
        if s.startswith("/"):
            s = s[1:]  # block delete switch off (LinuxCNC's default): the line runs
        if _PLAIN_LINE.fullmatch(s):
            pairs = _PLAIN_WORD.findall(s)
            plain = {a: float(v) for a, v in pairs}
            if len(plain) == len(pairs) and all(map(math.isfinite, plain.values())):
                if notes:
                    self._say(notes)
                self.execute((), (), plain)
                return
        words: dict[str, float] = {}
        gs: list[float] = []
        ms: list[int] = []
        pending: list[tuple] = []
        n_seen = False
        i = 0
        n = len(s)
        while i < n:
            c = s[i]
            if c == "#":
                if self.dialect == "grbl":
                    raise self.err(s, "grbl has no parameters", "use --dialect linuxcnc")
                if s.startswith("#<", i):
                    m = _NAME.match(s, i + 1)
                    if not m:
                        raise self.err(s[i:], "named parameter without '>'", "write #<name>")
                    ref, j = ("n", m.group(1)), m.end()
                else:
                    v, j = self.value(s, i + 1)
                    ref = ("i", self._param_index(v, s[i:j]))
                if j >= n or s[j] != "=":
                    raise self.err(s[i:j + 1], "parameter on its own must be an assignment",
                                   "write #1=value")
                v, i = self.value(s, j + 1)
                pending.append((ref, v))
                continue
            if c == "[" or c.isdigit():
                raise self.err(s[i:i + 10], "a value without a letter", "write a word like X1")
            letter = c
            if letter not in _LETTERS or (letter == "e" and self.dialect == "grbl"):
                if c == "%":  # (a '%' line of its own that opens or ends a program never gets here)
                    raise self.err("%", "'%' is read only as a line of its own that opens the "
                                   "file and then ends the program (LinuxCNC refuses this "
                                   "line: 'Bad character '%' used'; the moves after it never "
                                   "run)", "end the program with M2 or M30 instead, or remove "
                                   "the '%' (and any comment beside it)")
                if c == "$":
                    raise self._grbl_system(s[i:])
                if c == "\ufeff":  # a Windows editor's UTF-8 "BOM"; LinuxCNC: "Bad character"
                    raise self.err("BOM", "a byte-order mark (U+FEFF, bytes EF BB BF: the "
                                   "file, or one pasted into it, was saved as 'UTF-8 with "
                                   "BOM'), which LinuxCNC refuses too", "save the file as "
                                   "UTF-8 without BOM (or ASCII)")
                if c == "\ufffd":  # what a byte that is no UTF-8 was read as (gcode_text)
                    raise self.err(c, "a byte that is no UTF-8 text, read as U+FFFD (the "
                                   "file, or a line pasted into it, was saved in another "
                                   "encoding such as Latin-1 or Windows-1252), which LinuxCNC "
                                   "refuses too ('Bad character')", "outside comments G-code "
                                   "is ASCII: remove the character, or save the file as UTF-8")
                if not c.isalpha():
                    raise self.err(c, f"bad character {c!r} (a word is a letter and a value)",
                                   "fix or remove it")
                try:
                    tok = f"{c.upper()}{self.value(s, i + 1)[0]:g}"
                except GcodeError:
                    tok = c.upper()
                raise self.err(tok, f"unsupported word {letter.upper()} (woodcam simulates a "
                               "3-axis mill: no A/B/C/U/V/W axes or other letters)",
                               "post-process for 3 axes")
            if self.dialect == "grbl" and i + 1 < n and s[i + 1] in "[#":
                raise self.err(s[i:i + 6], "grbl has no expressions or parameters",
                               "use --dialect linuxcnc")
            at = i
            if letter == "n" and self.dialect != "grbl" and not _LINE_NUMBER.match(s, i + 1):
                raise self.err(_N_WORD.match(s, i).group(0).upper(), "a line number must be "
                               "digits, optionally '.' and digits (N10, N10.1); LinuxCNC "
                               "refuses a sign, expression or parameter there ('Bad format "
                               "unsigned integer')", "write N10 or remove the N word")
            v, i = self.value(s, i + 1)
            if letter == "g":
                gs.append(v)
            elif letter == "m":
                ms.append(v)
            elif letter == "n":
                if self.dialect == "grbl":  # grbl reads N anywhere on the line, once
                    if n_seen:
                        raise self.err(f"N{v:g}", "word N twice on one line", "keep one")
                    n_seen = True
                elif at:  # LinuxCNC: "Bad character 'n' used"
                    raise self.err(f"N{v:g}", "a line number (N word) in the middle of a line: "
                                   "LinuxCNC reads N only as the first word of a line",
                                   "move it to the start of the line or remove it")
                continue
            else:
                if letter in words:
                    raise self.err(f"{letter.upper()}{v:g}", f"word {letter.upper()} twice on "
                                   "one line", "keep one")
                words[letter] = v
        for ref, v in pending:  # the end-of-line assignment rule
            if ref[0] == "n" and (ref[1] in _PREDEFINED or ref[1] in _RETURNED):
                raise self.err(f"#<{ref[1]}>", f"#<{ref[1]}> is a read-only predefined "
                               "parameter (LinuxCNC: 'Cannot assign to read-only parameter')",
                               "use another name")
            if ref[0] == "i" and ref[1] in _READ_ONLY_NUM:
                raise self.err(f"#{ref[1]}", f"#{ref[1]} is a read-only system parameter "
                               "(LinuxCNC: 'Parameter is readonly')", "use another parameter")
            if ref[0] == "i" and ref[1] in _TOOLCHANGER_FAULT:
                # LinuxCNC takes the assignment without a word and reads the machine's value
                # over it: the value assigned is dropped, so woodcam refuses it
                raise self.err(f"#{ref[1]}", f"#{ref[1]} is the tool changer's fault "
                               f"{_TOOLCHANGER_FAULT[ref[1]]}, which the machine sets (LinuxCNC "
                               "accepts the assignment but reads the machine's value, 0 here, "
                               "over it)", "use another parameter")
            if ref[0] == "n":
                (self.globals if ref[1].startswith("_") else self.locals)[ref[1]] = v
            else:
                self.p[ref[1]] = v
        if notes:
            self._say(notes)
        if gs or ms or words:
            self.execute(gs, ms, words)

    def _say(self, notes) -> None:
        """Say the line's message comment ``notes`` (``[(kind, text)]``, split_comments):
        into :attr:`messages` MSG as written and DEBUG (while #5599 is on, as LinuxCNC) with
        the parameters' values put in, which LinuxCNC shows on the operator's screen; into
        :attr:`printed` PRINT, values put in too, which LinuxCNC writes to its standard output
        (the terminal it was started from) and never shows the operator."""
        for kind, text in notes:
            if kind != "msg" and self.dialect != "linuxcnc":
                continue  # grbl and Fanuc read (DEBUG,...), (PRINT,...) and (ABORT,...) as comments
            if kind == "msg":
                self.messages.append((self.line_no, text))
            elif kind == "abort":
                said = self._expand(text, "ABORT").strip()
                raise self.err(f"(ABORT,{text})", f"the program stops itself here: LinuxCNC "
                               f"ends it with the error '{said}' (its moves up to this line are "
                               "cut, none after)", "this is the program's own (ABORT,...): "
                               "satisfy the condition that leads to it, or remove it")
            elif kind == "print":
                self.printed.append((self.line_no, self._expand(text, "PRINT").strip()))
            elif self.p.get(5599, 0.0) > 0:
                self.messages.append((self.line_no, self._expand(text, "DEBUG").strip()))

    def _expand(self, text: str, kind: str) -> str:
        """``text`` of a (DEBUG,...) or (PRINT,...) comment with each ``#n``, ``#<name>`` put
        as LinuxCNC 2.9 puts it (its convert_param_comment): the value as C's ``%lf`` (six
        decimals; within 1e-4 of 0 as 0.000000, its 'equal'), ``######`` for a parameter it
        does not have (an unset name, a number over 5601) or a value over 29 characters; a
        name is read to its ``>`` without blanks, in lower case; a ``#`` followed by neither
        stays. A value woodcam cannot know shows as ``#n?`` (a probe result) or says what it
        is (the tool table, :meth:`_tool_entry_in_message`), with a warning."""
        self._message_pass += 1
        out = []
        i, n = 0, len(text)
        while i < n:
            j = text.find("#", i)
            if j < 0:
                out.append(text[i:])
                break
            out.append(text[i:j])
            i = j + 1
            ref = None
            if i < n and text[i] in "0123456789":
                m = _DIGITS.match(text, i)
                i = m.end()
                ref = "#" + m.group(0)
                k = int(m.group(0))
                value = (None if k > 5601 else 0.0 if k == 0 else
                         self._tool_entry_in_message(k, ref, kind) if k in _TOOL_ENTRY else
                         lambda k=k, ref=ref: self.get_num(k, ref))
            elif i < n and text[i] == "<" and ">" in text[i:]:
                close = text.find(">", i)
                name = "".join(c for c in text[i + 1:close] if c not in _C_SPACE).lower()
                ref, i = f"#<{name}>", close + 1
                value = self._named_in_message(name, ref)
            elif i < n and text[i] != "<":
                out.append("#")  # (the character after it is read as text)
                continue
            else:
                # LinuxCNC stops there and shows what an earlier message left in its buffer
                self._warn_message(f"({kind},...) ends in an unfinished parameter "
                                   f"'{text[j:]}': LinuxCNC shows left-over text of an earlier "
                                   "message after the text before it; write #1 or #<name>, or "
                                   "remove the '#'")
                break
            if isinstance(value, str):
                out.append(value)
                continue
            if callable(value):
                try:
                    value = value()
                except GcodeError as e:
                    self._warn_message(f"({kind},...) reads {ref}, which woodcam cannot know "
                                       f"({e.rule}): the message shows {ref}? for it")
                    out.append(f"{ref}?")
                    continue
            out.append(_lf(value))
        return "".join(out)

    def _tool_entry_in_message(self, k: int, ref: str, kind: str) -> float | str:
        """``#k`` (5401-5413) in a DEBUG/PRINT text (:func:`tool_entry_in_message`), its
        warning warned once for the line."""
        shown, warning = tool_entry_in_message(k, ref, kind, self.tool, self.tool_diameters_mm)
        if warning:
            self._warn_message(warning)
        return shown

    def _named_in_message(self, name: str, word: str):
        """The value of ``#<name>`` in a DEBUG/PRINT text: a number, ``None`` where LinuxCNC
        has no such parameter, or a function that reads it or raises :class:`GcodeError`
        where woodcam cannot know it."""
        known = _PREDEFINED.get(name)
        if known is not None or name in _RETURNED:
            return lambda: self.get_named(name, word)
        d = self.globals if name.startswith("_") else self.locals
        return d.get(name)

    def execute(self, gs, ms, w):
        if (not gs and not ms and self.motion in (0.0, 1.0) and _PLAIN_WORDS.issuperset(w)):
            # short path, same effect as below: only feed and axis words in G0/G1
            if "f" in w:
                if w["f"] < 0:
                    raise self.err(f"F{w['f']:g}", "negative feed rate", "give F >= 0")
                self.feed = w["f"] * self.scale
            self.cycle_il = None
            axis = [a for a in "xyz" if a in w]
            if axis:
                self.move(w, axis, False)
            return
        g: set[float] = set()
        for v in gs:
            c = round(v, 1)
            if v in (70.0, 71.0):  # Vectric's Mach3 posts open with "G00G21G17G90G40G49G80 G71"
                raise self.err(f"G{v:g}", f"G{v:g} is an old {'inch' if v == 70 else 'mm'} units "
                               f"code (Mach3, old Fanuc posts); {_OLD_UNITS_READ[self.dialect]}",
                               f"replace it by G{20 if v == 70 else 21} (or remove it where "
                               f"the program has G{20 if v == 70 else 21} already), or post "
                               f"for {_CONTROLLER[self.dialect]}")
            if abs(v - c) <= 1e-4 and c in _G_NOT_SIMULATED:
                raise self._not_simulated(f"G{v:g}", _G_NOT_SIMULATED[c])
            if (abs(v - c) > 1e-4 or c not in _G_KNOWN) and c not in _G_REFUSED:
                raise self.err(f"G{v:g}", "unsupported G code (woodcam reads the G codes "
                               "listed in woodcam.toolpath.interpreter)",
                               "post-process the program for a 3-axis mill")
            if c in _G_REFUSED:
                raise self.err(f"G{v:g}", _G_REFUSED[c], "post-process without it")
            if c in g and c != 80.0:  # LinuxCNC counts "G0 G0" as two codes (G80 G80 passes)
                name = next(n for n, codes in _G_GROUPS.items() if c in codes)
                raise self.err(f"G{c:g} G{c:g}", f"two {name} G codes on one line",
                               "keep one")
            g.add(c)
        for name, codes in _G_GROUPS.items():
            hit = g & codes
            if len(hit) > 1:
                if name == "motion" and hit & {80.0} and len(hit) == 2:
                    g.discard(80.0)  # G0 G80: LinuxCNC 2.9 and Fanuc take the motion code
                    continue
                raise self.err(" ".join(f"G{c:g}" for c in sorted(hit)),
                               f"two {name} G codes on one line", "keep one")
        if len(ms) > MAX_M_PER_LINE and self.dialect != "grbl":
            raise self.err(" ".join(f"M{v:g}" for v in ms), f"more than {MAX_M_PER_LINE} M "
                           "codes on one line (LinuxCNC's limit)", "split the line")
        for name, codes in _M_GROUPS.items():
            hit = [v for v in ms if v in codes]
            if len(hit) > 1:
                raise self.err(" ".join(f"M{v:g}" for v in hit),
                               f"two {name} M codes on one line", "keep one")
        mset = set()
        for v in ms:
            if v == math.floor(v) and int(v) in _M_WARN:
                self.warn(f"M{int(v)} ({_M_WARN[int(v)]}) is not simulated")
                mset.add(int(v))
                continue
            if v in (98.0, 99.0):
                if self.dialect == "grbl":
                    raise self.err(f"M{v:g}", "grbl has no subprograms (M98 calls, M99 returns)",
                                   "pass --dialect fanuc or linuxcnc, whose controls run them")
                if v == 98.0 or self._frames:
                    raise self.err(f"M{v:g}", f"M{v:g} after other words: woodcam reads a "
                                   "subprogram call or return only as the first word of its "
                                   "line (after its N word), as LinuxCNC does",
                                   f"put M{v:g} on a line of its own")
                mset.add(99)  # the main program's M99: ends the pass (see below)
                continue
            if v == math.floor(v) and int(v) in _M_NOT_SIMULATED:
                raise self._not_simulated(f"M{v:g}", _M_NOT_SIMULATED[int(v)])
            if v != math.floor(v) or int(v) not in _M_KNOWN:
                raise self.err(f"M{v:g}", "unsupported M code (woodcam reads M0-M9, M30, "
                               "M48-M53, M60, M61; M19, M62-M68 and M100-M199 with a warning)",
                               "remove it or post-process for a 3-axis mill")
            mset.add(int(v))
        for k in ("t", "l", "h"):
            if k in w and (w[k] != math.floor(w[k]) or w[k] < 0 or w[k] > 1e9):
                # (the nearest whole number without its sign: "write L0" for a cycle's L-2 was
                # refused again, as cycle repeats L must be 1 or more)
                raise self.err(f"{k.upper()}{w[k]:g}", "must be a non-negative integer",
                               f"write {k.upper()}{abs(round(w[k])):d}" if abs(w[k]) < 1e9
                               else "fix the number")
        if mset & {66, 67, 68}:
            self._analog_io(mset, w)
        # 3-5. feed mode (LinuxCNC zeroes F on every G93/G94/G95), feed, spindle, tool
        if g & {93.0, 94.0, 95.0}:
            self.feed = 0.0
        if "f" in w:
            if w["f"] < 0:
                raise self.err(f"F{w['f']:g}", "negative feed rate", "give F >= 0")
            scale = self.scale
            if self.dialect == "grbl" and g & {20.0, 21.0}:  # grbl reads F in its line's units
                scale = MM_PER_INCH if 20.0 in g else 1.0
            self.feed = w["f"] * scale
        if "s" in w:
            if w["s"] < 0:
                raise self.err(f"S{w['s']:g}", "negative spindle speed", "give S >= 0")
            self.spindle = w["s"]
        if "t" in w:
            self.selected = int(w["t"])
            self._t_pending = True
        if 61 in mset:  # M61 Qn: the loaded tool is n, no change
            if "q" not in w or w["q"] != math.floor(w["q"]) or w["q"] < 0:
                raise self.err("M61", "M61 needs Q = a tool number", "write M61 Q1")
            # the selected tool stays (LinuxCNC sets only the loaded one): a later M6 loads the
            # T word's tool, not M61's
            self.tool = int(w["q"])
        if 6 in mset:
            self.tool = self.selected
            self._t_pending = False
            if self.dialect == "linuxcnc":
                # LinuxCNC stops the spindle for a tool change (TOOL_CHANGE_WITH_SPINDLE_ON
                # is off by default); an M3/M4 on the same line starts it again (step 7 of its
                # order of execution, after the change at step 6)
                self.spindle_on = False
        if 66 in mset:  # the input it waits for lands in #5399: not known from here on
            self.p.pop(5399, None)
        if mset & {3, 4}:
            self.spindle_on = True
            self.spindle_cw = 3 in mset
        if 7 in mset:
            self.coolant["mist"] = True
        if 8 in mset:
            self.coolant["flood"] = True
        if 9 in mset:
            self.coolant.update(mist=False, flood=False)
        if mset & set(range(48, 54)):
            self._override_codes(mset, w)
        if mset & {5, 19}:  # M19 orients the spindle: it stands until M3/M4 (LinuxCNC)
            self.spindle_on = False
        if 4.0 in g:
            if "p" not in w or w["p"] < 0:
                raise self.err("G4", "dwell needs P >= 0 (seconds)", "write G4 P0.5")
        for c in (17, 18, 19):
            if float(c) in g:
                self.plane = c
        if 20.0 in g:
            self.inch = True
        if 21.0 in g:
            self.inch = False
        if 43.0 in g and "h" not in w:
            self.warn("G43 without H uses the loaded tool's length from the machine's tool "
                      "table, which woodcam does not know: tool table lengths are taken as 0 "
                      "(woodcam measures tools from the tip), so the offset becomes 0")
        if g & {43.0, 43.1, 49.0}:
            self._tool_length_offset(g, w)
        for c in _CS:
            if c in g:
                self.cs = _CS.index(c) + 1
                self.p[5220] = float(self.cs)
                self.g5x = [self.p.get(_cs_base(self.cs) + i, 0.0) for i in range(3)]
        if 90.0 in g:
            self.incremental = False
        if 91.0 in g:
            self.incremental = True
        if 90.1 in g:
            self.arc_incremental = False
        if 91.1 in g:
            self.arc_incremental = True
        if 98.0 in g:
            self.retract_old_z = True
        if 99.0 in g:
            self.retract_old_z = False
        motion_here = [c for c in g if c in _MOTION]
        axis = [a for a in "xyz" if a in w]
        nonmodal = g & _G_GROUPS["non-modal"]
        # LinuxCNC runs the modal arc on a line with I/J/K and no axis words ("I5" after a G2:
        # a full circle), as it runs the modal motion on a line with axis words
        modal_arc = (self.dialect == "linuxcnc" and not motion_here and not axis
                     and self.motion in (2.0, 3.0) and not nonmodal & _AXIS_CODES
                     and any(k in w for k in "ijk"))
        if (self.dialect == "linuxcnc" and 4.0 in g and motion_here
                and motion_here[0] in (2.0, 3.0)):
            raise self.err(f"G4 G{motion_here[0]:g}", f"G4 and G{motion_here[0]:g} on one line "
                           "both read P (dwell seconds, arc turns); LinuxCNC refuses the line",
                           "put the dwell on a line of its own")
        self._unused_words(g, mset, w, motion_here, axis or modal_arc)
        eff = motion_here[0] if motion_here else self.motion
        if 19 in mset and "r" in w and not (eff in (2.0, 3.0) or eff in _CYCLES or 10.0 in g):
            w = {k: v for k, v in w.items() if k != "r"}  # M19's R: the angle, no arc
        if 10.0 in g:
            self.g10(w)
        elif nonmodal & {28.0, 30.0}:
            self.home(30.0 if 30.0 in g else 28.0, w)
        elif nonmodal & {28.1, 30.1}:
            base = 5161 if 28.1 in g else 5181
            for i in range(3):  # the controlled point (module docstring)
                self.p[base + i] = self.pos[i] + self.tlo[i]
        elif 92.0 in g:
            if not axis:
                raise self.err("G92", "G92 needs axis words", "write G92 X0 Y0 Z0")
            for i, a in enumerate("xyz"):
                if a in w:
                    # G92 makes the current point read w[a]: offset = pos - g5x - value
                    self.g92[i] = self.pos[i] - self.g5x[i] - w[a] * self.scale
                    self.p[5211 + i] = self.g92[i]
            self.p[5210] = 1.0
        elif 52.0 in g:
            # LinuxCNC's local offset: the G92 offset set to the words themselves (mm in the
            # program's units, G90 or G91 alike), the unnamed axes' offsets kept; G92.1 clears
            # it, G92.3 restores it (measured against LinuxCNC 2.9's interpreter)
            if self.dialect == "grbl":
                raise self.err("G52", "grbl has no G52 local offset",
                               "use G92 or G10 L20, or pass --dialect linuxcnc")
            if not axis:
                raise self.err("G52", "G52 needs axis words", "write G52 X10 Y0 (G52 X0 Y0 Z0 "
                               "cancels it)")
            for i, a in enumerate("xyz"):
                if a in w:
                    self.g92[i] = w[a] * self.scale
                    self.p[5211 + i] = self.g92[i]
            self.p[5210] = 1.0
        elif 92.1 in g or 92.2 in g:
            self.g92 = [0.0] * 3
            if 92.1 in g:
                for i in range(3):
                    self.p[5211 + i] = 0.0
                self.p[5210] = 0.0
        elif 92.3 in g:
            self.g92 = [self.p.get(5211 + i, 0.0) for i in range(3)]
        if nonmodal & _AXIS_CODES or (43.1 in g and not motion_here):
            # the axis words belonged to the non-modal code, or are G43.1's dynamic tool
            # length offset (LinuxCNC: "G43.1 Z2" moves nothing; with a motion code on the line
            # both read them)
            axis = []
        self.motion_before = self.motion
        if motion_here:
            self.motion = motion_here[0] if motion_here[0] != 80.0 else None
            self.motion_cancelled = self.motion_cancelled or self.motion is None
        if self.motion not in _CYCLES:
            self.cycle_il = None
        if 53.0 in g:
            # LinuxCNC's rule ("Must use g0 or g1 with g53"): the line's motion is G0 or G1, a
            # code on the line or the modal one that its axis words use; "G53 G0" without axis
            # words moves nothing and is accepted (it was refused), a bare "G53" is not
            if self.motion not in (0.0, 1.0) or not (axis or motion_here):
                raise self.err("G53", "G53 needs G0 or G1 on its line, or axis words in G0 or G1 "
                               "mode (LinuxCNC: 'Must use g0 or g1 with g53')", "write G53 G0 Z0")
            if self.incremental:
                raise self.err("G53", "G53 in incremental mode (G91)", "use G90")
        full_circle = modal_arc or (bool(motion_here) and self.motion in (2.0, 3.0) and not axis
                                    and any(k in w for k in "ijk"))  # G2 I5: a full circle
        if axis or full_circle or (motion_here and self.motion in _CYCLES):
            if self.motion is None:
                # only linuxcnc starts without one (LinuxCNC's interpreter starts in G80; grbl's
                # and Fanuc's controls in G0); elsewhere a G80 has cancelled it
                why = "G80 cancelled it" if self.motion_cancelled else "LinuxCNC starts in G80, without one"
                raise self.err("".join(f"{a.upper()}{w[a]:g}" for a in axis),
                               f"axis words without a motion mode ({why})",
                               "add G0 or G1 to the line")
            self.move(w, axis, 53.0 in g)
        elif any(k in w for k in "ijk") or ("r" in w and self.motion not in _CYCLES
                                            and 10.0 not in g):  # (G10 L2's R: read there)
            k = next(k for k in "ijkr" if k in w)
            raise self.err(f"{k.upper()}{w[k]:g}", "arc words without an end point",
                           "give X/Y/Z with G2/G3")
        elif self.dialect == "linuxcnc" and motion_here and self.motion in (2.0, 3.0):
            # LinuxCNC runs a G2/G3 written on a line even without axis words: with neither
            # an end nor a centre it refuses the line ("R i j k words all missing for arc")
            raise self.err(f"G{self.motion:g}", f"G{self.motion:g} with no end point (X/Y/Z) "
                           "and no centre (I/J/K or R): LinuxCNC refuses the line",
                           f"give the arc's end and centre, or remove G{self.motion:g} "
                           "(the next arc line sets the mode)")
        if mset & {2, 30}:
            self.ended = True
        if 99 in mset:
            self.ended = True
            self.warn("M99 in the main program: the control starts the program again from the "
                      "top and repeats it forever (LinuxCNC, Fanuc and Mach3 alike); woodcam "
                      "simulated one pass; replace this M99 with M30 (or M2) to stop after one "
                      "pass")

    def _grbl_system(self, cmd: str) -> GcodeError:
        """The refusal of grbl's ``$`` system command ``cmd`` (the rest of its line, lower
        case): not G-code (LinuxCNC: "Bad character '$' used"); grbl senders pass it to the
        controller, which homes, jogs or reports. woodcam refuses it in every dialect, naming
        what it does: homing and jogging move the machine to where the program does not say
        (the machine's switches, a jog's own frame), the rest change settings or report."""
        word = cmd[:12].upper()
        for prefix, what, fix in _GRBL_SYSTEM:
            if cmd.startswith(prefix) or (prefix == "<n>=" and re.match(r"\$\d+=", cmd)):
                return self.err(word, f"grbl system command ({what}), not G-code: a grbl "
                                "sender passes it to the controller and woodcam does not "
                                "simulate it", fix)
        return self.err(word, "grbl system command (a settings, state or build report), not "
                        "G-code: woodcam does not simulate it",
                        "remove the line (it does not move the machine)")

    def _override_codes(self, mset, w):
        """M48/M49 switch both overrides on/off; M50 (feed override), M51 (speed override),
        M52 (adaptive feed) and M53 (feed hold) switch theirs off with P0, else on (as
        LinuxCNC 2.9: no P is on)."""
        if 48 in mset or 49 in mset:
            self.overrides.update(feed=48 in mset, speed=48 in mset)
        on = w.get("p", 1.0) != 0
        for code, key in ((50, "feed"), (51, "speed"), (52, "adaptive"), (53, "hold")):
            if code in mset:
                self.overrides[key] = on

    def _analog_io(self, mset, w):
        """LinuxCNC's checks of M66 (wait on digital input P or analog input E, wait type L,
        timeout Q s) and M67/M68 (analog output E set to Q): read, not simulated, but a line
        LinuxCNC refuses is refused here too."""
        if 66 in mset:
            if "p" in w and "e" in w:
                raise self.err(f"P{w['p']:g} E{w['e']:g}", "M66 selects a digital input (P) or "
                               "an analog one (E), not both", "keep one")
            if w.get("p", w.get("e", -1.0)) < 0:
                raise self.err("M66", "M66 needs P (a digital input) or E (an analog input), "
                               ">= 0", "write M66 P0 L0")
            if w.get("l", 0.0) != 0 and w.get("q", 0.0) <= 0:
                raise self.err(f"L{w['l']:g}", "M66 waiting for an edge or a level (L not 0) "
                               "needs a timeout Q > 0 (seconds)", "write e.g. M66 P0 L3 Q5")
        for code in (67, 68):
            if code in mset and w.get("e", -1.0) < 0:
                raise self.err(f"M{code}", f"M{code} needs E = the analog output, >= 0",
                               f"write M{code} E0 Q50")

    def _unused_words(self, g, mset, w, motion_here, axis):
        """LinuxCNC refuses a P/Q/R/L/E/H/I/J/K word that no code of the line uses.
        ``axis``: true when the line runs the modal motion (axis words, or LinuxCNC's I/J/K
        under a modal arc)."""
        eff = motion_here[0] if motion_here else (self.motion if axis else None)
        uses = {
            "q": bool(g & {10.0, 64.0}) or eff in (73.0, 83.0)
            or bool(mset & {19, 61, 66, 67, 68}),
            "r": 10.0 in g or eff in (2.0, 3.0) or eff in _CYCLES or 19 in mset,
            "p": bool(g & {4.0, 10.0, 64.0}) or eff in (2.0, 3.0, 82.0, 86.0, 89.0)
            or bool(mset & {19, 50, 51, 52, 53, 62, 63, 64, 65, 66, 67, 68}),
            "l": 10.0 in g or eff in _CYCLES or 66 in mset,
            "e": bool(mset & {66, 67, 68}),
            "h": 43.0 in g,
            "d": bool(g & {41.0, 42.0, 41.1, 42.1}),
        }
        for k, used in uses.items():
            if k in w and not used:
                raise self.err(f"{k.upper()}{w[k]:g}", f"{k.upper()} word with no G or M code "
                               "on the line that uses it (LinuxCNC refuses it too)",
                               "remove it or add the code it belongs to")
        if eff not in (2.0, 3.0) and 10.0 not in g:
            for k in "ijk":
                if k in w:
                    raise self.err(f"{k.upper()}{w[k]:g}", f"{k.upper()} word with no G2/G3 "
                                   "to use it", "give X/Y/Z with G2/G3")

    # -- non-modal codes --------------------------------------------------------------------
    def g10(self, w):
        ln = w.get("l")
        if ln not in (2.0, 20.0):
            raise self.err(f"G10 L{ln:g}" if ln is not None else "G10", "woodcam reads G10 L2 "
                           "and G10 L20 (work offsets); tool tables come from --tools",
                           "remove it")
        if "p" not in w:  # LinuxCNC: "P value out of range (0-9) with G10 L2"
            raise self.err(f"G10 L{ln:g}", f"G10 L{ln:g} without P (the coordinate system: 0 "
                           "the active one, 1-9 G54-G59.3); LinuxCNC refuses it",
                           f"write e.g. G10 L{ln:g} P1 X0 Y0 Z0")
        p = w["p"]
        if p != math.floor(p) or not 0 <= p <= 9:
            raise self.err(f"P{p:g}", "G10 P must be 0 (active) or 1-9 (G54-G59.3)",
                           "fix P")
        if "r" in w and ln == 20.0:
            raise self.err(f"R{w['r']:g}", "R (a rotation) is not allowed in G10 L20 "
                           "(LinuxCNC refuses it)", "remove R, or set the rotation with G10 L2")
        if "r" in w and w["r"] != 0:  # (R0, no rotation, is read)
            raise self.err(f"R{w['r']:g}", "G10 L2 R (rotated coordinate systems) is not "
                           "simulated", "remove the rotation")
        n = int(p) or self.cs
        base = _cs_base(n)
        for i, a in enumerate("xyz"):
            if a not in w:
                continue
            if ln == 2.0:
                val = w[a] * self.scale
            else:  # L20: the current point shall read w[a] in system n
                val = self.pos[i] - self.g92[i] - w[a] * self.scale
            self.p[base + i] = val
            if n == self.cs:
                self.g5x[i] = val

    def _tool_length_offset(self, g, w):
        """G43 H (the tool table's length: 0, as woodcam's tools are measured from the tip; the
        oracle's table holds 0 too), G43.1 (the axes it names, in program units; the others
        keep theirs, as LinuxCNC) or G49 (none). The control keeps the controlled point (the
        spindle) where it is, so the tip it moves by the program's coordinates is now the
        change lower: woodcam's tip position moves by it (no motion: the spindle stands)."""
        new = [0.0, 0.0, 0.0] if g & {43.0, 49.0} else list(self.tlo)
        if 43.1 in g:
            for i, a in enumerate("xyz"):
                if a in w:
                    new[i] = w[a] * self.scale
        self.pos = [p - (n - o) for p, n, o in zip(self.pos, new, self.tlo)]
        self.tlo = new

    def home(self, code, w):
        """G28/G30: rapid through the (optional) intermediate point to the stored home
        (#5161-#5163 / #5181-#5183, machine frame; woodcam stores its start position there)."""
        base = 5161 if code == 28.0 else 5181
        axis = [a for a in "xyz" if a in w]
        if axis:
            self.emit(TRAVERSE, self._target(w, axis))
        idx = [i for i, a in enumerate("xyz") if a in w] if axis else [0, 1, 2]
        end = list(self.pos)
        for i in idx:  # the home holds the controlled point: the tip is the offset lower
            end[i] = self.p.get(base + i, 0.0) - self.tlo[i]
            self.known[i] = True
        self.emit(TRAVERSE, end)

    # -- motion -----------------------------------------------------------------------------
    def _target(self, w, axis, machine=False):
        if machine:
            end = list(self.pos)
            for i, a in enumerate("xyz"):
                if a not in w:
                    continue
                end[i] = w[a] * self.scale - self.tlo[i]  # G53 places the controlled point
                if self.mzero is None:  # not known: see the module docstring
                    key = "z" if a == "z" else "xy"
                    if self.line_no not in self._g53_unplaced[key]:
                        self._g53_unplaced[key].append(self.line_no)
                    if a == "z":
                        end[i] = max(self.start_z, self.pos[i])
            return end
        if (not self.incremental and not self.inch and not any(self.g5x)
                and not any(self.g92)):
            # absolute mm without offsets (most programs): the general path's arithmetic is
            # the identity here, so this gives the same numbers bit for bit
            end = list(self.pos)
            for i, a in enumerate("xyz"):
                if a in w:
                    end[i] = w[a] + 0.0  # as the general path: -0.0 becomes 0.0
            return end
        prog = self.to_program(self.pos)
        for i, a in enumerate("xyz"):
            if a in w:
                prog[i] = prog[i] + w[a] if self.incremental else w[a]
        end = self.to_machine(prog)
        for i, a in enumerate("xyz"):  # untouched axes stay bit-exact
            if a not in w:
                end[i] = self.pos[i]
        return end

    def move(self, w, axis, machine):
        mode = self.motion
        for i, a in enumerate("xyz"):
            if a in axis and not self.incremental:
                self.known[i] = True
        if mode in _CYCLES:
            return self.cycle(w)
        if mode in (1.0, 2.0, 3.0) and self.feed <= 0:
            raise self.err(f"G{mode:g}", "feed move with feed rate 0 (no F yet)",
                           "set F before cutting")
        end = self._target(w, axis, machine)
        if mode in (0.0, 1.0):
            if any(k in w for k in "ijk") or ("r" in w):
                k = next(k for k in "ijkr" if k in w)
                raise self.err(f"{k.upper()}{w[k]:g}", "arc word on a straight move",
                               "use G2/G3 for arcs")
            self.emit(TRAVERSE if mode == 0.0 else FEED, end)
            return
        self.arc(w, end, cw=(mode == 2.0))

    def arc(self, w, end, cw):
        a1, a2, an = _PLANES[self.plane]
        names = _CENTRE[self.plane]
        code = f"G{2 if cw else 3}"
        for k in set("ijk") - set(names):
            if k in w:
                raise self.err(f"{k.upper()}{w[k]:g}", f"centre word {k.upper()} is not in "
                               f"plane G{self.plane}", f"use {names.upper()} or change plane")
        turns = 1
        if "p" in w:
            if w["p"] != math.floor(w["p"]) or w["p"] < 1:
                raise self.err(f"P{w['p']:g}", "arc turns P must be an integer >= 1", "fix P")
            turns = int(w["p"])
        s1, s2 = self.pos[a1], self.pos[a2]
        e1, e2 = end[a1], end[a2]
        tol = _ARC_ABS_TOL["in" if self.inch else "mm"] * self.scale  # mm
        if "r" in w:
            if any(k in w for k in "ijk"):
                raise self.err(f"R{w['r']:g}", "both R and I/J/K on one arc", "give one form")
            r = w["r"] * self.scale
            d1, d2 = e1 - s1, e2 - s2
            dist = math.hypot(d1, d2)
            if dist == 0:
                raise self.err(f"R{w['r']:g}", "R-form arc with end = start (a full circle has "
                               "no unique centre)", "use the I/J/K form for full circles")
            half = dist / 2
            if half - abs(r) > _ARC_R_TOL_MM:
                raise self.err(f"R{w['r']:g}", f"arc radius {say_length(abs(r), 'g')} too small to reach "
                               f"the end point (half chord {say_length(half, 'g')}; LinuxCNC's tolerance "
                               f"{say_length(_ARC_R_TOL_MM, 'g')})", "fix R or the end")
            h = math.sqrt(max(r * r - half * half, 0.0)) / dist
            # centre on the right of start->end for G2 with R > 0 (LinuxCNC/grbl convention)
            if cw == (r > 0):
                h = -h
            c1, c2 = s1 + d1 / 2 - h * d2, s2 + d2 / 2 + h * d1
        else:
            if not any(k in w for k in names):
                raise self.err(code, f"arc needs R or {names.upper()}", "give the arc centre")
            o1 = w.get(names[0], 0.0) * self.scale
            o2 = w.get(names[1], 0.0) * self.scale
            if self.arc_incremental:
                c1, c2 = s1 + o1, s2 + o2
            else:  # G90.1: centre in program coordinates
                both = " and ".join(sorted(names.upper()))
                for k in names:
                    if k not in w:  # LinuxCNC refuses it ("J word missing in absolute center
                        # arc"): the word is a coordinate, and a missing one is no "unchanged"
                        raise self.err(code, f"{k.upper()} word missing in an absolute-centre "
                                       f"arc (G90.1: {both} are the centre's coordinates)",
                                       f"give both {both}, or G91.1 for centres relative "
                                       "to the start")
                prog_c = [0.0, 0.0, 0.0]
                prog_c[a1] = w[names[0]]
                prog_c[a2] = w[names[1]]
                mc = self.to_machine(prog_c)
                c1, c2 = mc[a1], mc[a2]
            r0 = math.hypot(s1 - c1, s2 - c2)
            r1 = math.hypot(e1 - c1, e2 - c2)
            if min(r0, r1) < _ARC_MIN_RADIUS_MM:
                raise self.err(code, f"zero-radius arc: radius {say_length(min(r0, r1), '.4g')} is below "
                               f"LinuxCNC's {say_length(_ARC_MIN_RADIUS_MM, 'g')}",
                               "replace the arc by a G1 to its end point")
            err = abs(r1 - r0)
            if err > 100 * tol or (err > tol
                                                          and err / max(r0, r1) > _ARC_REL_TOL):
                raise self.err(code, f"radius to end of arc {say_length(r1, '.4f')} differs from radius "
                               f"to start {say_length(r0, '.4f')} (LinuxCNC's tolerance {say_length(tol, '.4g')} "
                               "and 0.1 %)", "fix the centre (I/J/K) or the end point")
        if not all(math.isfinite(v) for v in (c1, c2)):
            raise self.err(code, "arc centre out of range", "fix the arc")
        self.emit(ARC, end, (c1, c2), -turns if cw else turns)

    def cycle(self, w):
        """Canned drilling cycles as LinuxCNC's convert_cycle expands them (G17, XY plane)."""
        code = f"G{self.motion:g}"
        if self.plane != 17:
            raise self.err(code, "drilling cycles are simulated in plane G17 only",
                           "switch to G17")
        if self.feed <= 0:
            raise self.err(code, "drilling with feed rate 0 (no F yet)", "set F")
        if self.motion == 86.0 and not self.spindle_on and self.dialect == "linuxcnc":
            # G86 stops the spindle at the bottom and starts it again: LinuxCNC refuses it with
            # the spindle stopped ("Spindle not turning in g86")
            raise self.err(code, "G86 (bore, spindle stop, rapid out) with the spindle stopped: "
                           "LinuxCNC refuses it ('Spindle not turning in g86')",
                           "start the spindle (M3 S...) before the G86 line")
        c = self.cyc
        if self.dialect == "linuxcnc" and self.motion_before != self.motion:
            # LinuxCNC carries R, Z, Q (G73/G83) and P (G82/G86/G89) over only from lines of
            # the same cycle code ("R clearance plane unspecified in cycle", "Dwell time p word
            # missing with g82", ...): a cycle code written after another mode needs them all
            needs = {"r": "R (the retract plane)", "z": "Z (the hole bottom)"}
            if self.motion in (73.0, 83.0):
                needs["q"] = "Q (the peck depth)"
            if self.motion in (82.0, 86.0, 89.0):
                needs["p"] = "P (the dwell at the bottom, seconds)"
            # (no mode: LinuxCNC starts in G80, and G80 cancels one)
            before = "G80" if self.motion_before is None else f"G{self.motion_before:g}"
            for k, what in needs.items():
                if k not in w:
                    raise self.err(code, f"{code} after {before} without {what}: LinuxCNC "
                                   f"keeps {k.upper()} only from lines of the same cycle code",
                                   f"give {k.upper()} on the line that starts {code}")
        if "r" in w:
            c["r"] = w["r"]
        if "z" in w:
            c["z"] = w["z"]
        if "q" in w:
            if w["q"] <= 0:
                raise self.err(f"Q{w['q']:g}", "peck depth Q must be > 0", "give Q > 0")
            c["q"] = w["q"]
        if "p" in w:
            c["p"] = w["p"]
        reps = 1
        if "l" in w:
            reps = int(w["l"])
            if not 1 <= reps <= MAX_CYCLE_REPEATS:
                raise self.err(f"L{reps}", f"cycle repeats L must be 1-{MAX_CYCLE_REPEATS}",
                               "fix L")
        if math.isnan(c["r"]) or math.isnan(c["z"]):
            raise self.err(code, "drilling cycle without R and Z", "give R (retract) and Z "
                           "(depth)")
        if self.motion in (73.0, 83.0) and math.isnan(c["q"]):
            raise self.err(code, f"{code} needs a peck depth Q", "give Q > 0")
        prog = self.to_program(self.pos)
        cur_z = prog[2]
        if self.cycle_il is None:  # LinuxCNC's "initial level": Z where the cycles began
            self.cycle_il = cur_z
        if self.incremental:
            # R counts from the initial level of the series, not from where the last hole left
            # the tool (LinuxCNC 2.9, measured: after a G99 retract to R the next "X5" line's R
            # is not taken from R)
            r = self.cycle_il + c["r"]
            bottom = r + c["z"]
        else:
            r, bottom = c["r"], c["z"]
        if bottom > r:
            raise self.err(code, f"cycle bottom Z {bottom:g} is above the retract plane R "
                           f"{r:g}", "fix Z or R")
        delta = c["q"]
        if self.motion in (73.0, 83.0) and (r - bottom) / delta > 100_000:
            raise self.err(f"Q{delta:g}", f"{(r - bottom) / delta:.3g} pecks in one hole (more "
                           "than 100,000)", "give a larger Q")
        rapid_delta = _RAPID_DELTA_IN * (1.0 if self.inch else MM_PER_INCH)
        x, y = prog[0], prog[1]
        # LinuxCNC 2.9's convert_cycle_xy (and measured): old = the initial level; below R it
        # is raised to R by a rapid at the tool's X/Y (the tool then at R); the retract plane
        # is R (G99) or old (G98); the first hole is reached at the tool's Z when above R,
        # else at the retract plane, the next repeats (L) at the retract plane. woodcam
        # travelled at the initial level in G98: after a hole with R3 above the initial Z1 it
        # dropped to Z1 to cross to the next hole (LinuxCNC stays at Z3)
        old = self.cycle_il
        if old < r:  # preliminary move up to the R plane
            self._cyc(TRAVERSE, x, y, r)
            old = cur_z = r
        clear = old if self.retract_old_z else r
        old_z = cur_z if cur_z > r else clear
        for _ in range(reps):
            if self.incremental:
                x += w.get("x", 0.0)
                y += w.get("y", 0.0)
            else:
                x, y = w.get("x", x), w.get("y", y)
            self._cyc(TRAVERSE, x, y, old_z)
            self._cyc(TRAVERSE, x, y, r)
            if self.motion == 83.0:
                depth = r - delta
                while depth > bottom:
                    self._cyc(FEED, x, y, depth)
                    self._cyc(TRAVERSE, x, y, r)
                    self._cyc(TRAVERSE, x, y, depth + rapid_delta)
                    depth -= delta
            elif self.motion == 73.0:
                depth = r - delta
                while depth > bottom:
                    self._cyc(FEED, x, y, depth)
                    self._cyc(TRAVERSE, x, y, depth + rapid_delta)
                    depth -= delta
            self._cyc(FEED, x, y, bottom)
            if self.motion == 85.0:  # LinuxCNC: G85 feeds out to R, G89 to the clearance
                self._cyc(FEED, x, y, r)
            elif self.motion == 89.0:
                self._cyc(FEED, x, y, clear)
            self._cyc(TRAVERSE, x, y, clear)
            old_z = clear  # LinuxCNC: the next repeat (L) travels at the clearance plane

    def _cyc(self, kind, x, y, z):
        self.emit(kind, self.to_machine([x, y, z]))
