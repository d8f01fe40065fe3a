"""Runs LinuxCNC's own RS274/NGC interpreter (Debian ``linuxcnc-uspace``'s ``gcode`` module,
the one its AXIS preview uses) on G-code files and prints canonical moves as JSON.

Run by :mod:`woodcam.toolpath.linuxcnc` with Debian's ``/usr/bin/python3`` (the module is built
for it, not for woodcam's virtualenv); never imported by woodcam. Input (stdin, JSON):
``{"files": [path, ...], "start_mm": [x, y, z], "timeout_s": t, "machine_zero_mm": [x, y, z],
"tool_diameters_mm": {"n": d, ...}}`` (the last two optional: zero, no diameters); output (stdout,
JSON): one ``{"moves": [...], "messages": [[line, text], ...], "printed": [[line, text], ...],
"said_order": [0 | 1, ...], "printed_unplaced": [...], "error": null | [line, message],
"result": code}`` per file (messages: the operator messages, ``(MSG,...)``/``(DEBUG,...)``; printed: the ``(PRINT,...)``
texts, which the interpreter writes to its standard output, not through the canon:
:func:`_mark_prints`; said_order: the two as the program said them, 0 a message, 1 a PRINT
text, :func:`_said_order`; printed_unplaced: ``[[index, lines], ...]``, the PRINT texts whose
line is not known, each with the lines that could have printed it, :func:`_printed`), moves as
woodcam's canonical tuples ``[kind, line, [x, y, z], [c1, c2] | null, rotation, plane,
feed_mm_min, spindle_rpm, tool, inch]`` in the
machine frame, mm, tool tip (LinuxCNC's canon reports program coordinates before the G5x/G92
offsets, which are added back here as AXIS does, and without the tool length offset, which is
not: AXIS adds it too and draws the controlled point, the spindle's gauge line, where a tool
with that length offset has its tip the offset lower; woodcam simulates the tip), shifted by
``machine_zero_mm``: the G54 offset is ``-machine_zero_mm``, so the moves come out in the G54
frame the start position is given in (as woodcam's interpreter does). The machine is metric
(external length units mm, the parameter file in mm), as woodcam's interpreter: a program reads
``#5161`` or ``#5221`` in mm (the canon calls still come in inches: the module converts them);
a move's ``inch`` is the G20/G21 mode it was programmed in (:meth:`_Canon.next_line`).
The tool table the interpreter reads (``get_tool``, again after each M6) has zero offsets and
the diameters of ``tool_diameters_mm`` (mm, the machine's units: a DEBUG/PRINT of ``#5410``
shows them whatever G20/G21, as ``rs274 -t``); its pocket 0 is the loaded tool's entry, as a
machine's is after a tool change (``#5400``, ``#<_current_tool>`` and ``#5401``-``#5413`` read
it; before, pocket 0 held no tool and they read 0 after an M6).
"""

import ctypes
import json
import os
import re
import shutil
import sys
import tempfile
import time

MM = 25.4
#: LinuxCNC's longest line (its LINELEN less the end): a longer one is "Command too long"
MAX_LINE = 252
_PRINT = re.compile(rb"\(([ \t]*print,)", re.IGNORECASE)  # LinuxCNC: blanks, any case, comma
_MARKED = re.compile(r"\x01(\d+)\x02(.*)")
_BLANKS = str.maketrans("", "", " \t\r")  # what LinuxCNC skips between words
_PLANE = {1: 17, 2: 19, 3: 18}  # CANON_PLANE_XY, YZ, XZ -> G17, G19, G18
# first/second axis (x=0, y=1, z=2) of an arc in each canon plane; the third is the normal
_AXES = {1: (0, 1, 2), 2: (1, 2, 0), 3: (2, 0, 1)}


def _tool_table(work):
    """LinuxCNC 2.9 keeps its tool table in a memory map created by the running machine's task;
    without one, a T word crashes the interpreter. Create it here with tools 1-99 of zero
    length (woodcam measures tools from the tip). The map is ``$HOME/.tool.mmap``, so HOME
    points at the run's scratch folder ``work``."""
    os.environ["HOME"] = work
    lib = ctypes.CDLL("libtooldata.so.0")
    buf = ctypes.create_string_buffer(1 << 20)
    lib._Z17tool_mmap_creatorPK13EMC_TOOL_STATi(buf, 0)
    lib._Z13tooldata_initb(ctypes.c_bool(False))
    lib._Z14tooldata_resetv()

    class _Tool(ctypes.Structure):
        _fields_ = [("toolno", ctypes.c_int), ("pocketno", ctypes.c_int),
                    ("offset", ctypes.c_double * 9), ("diameter", ctypes.c_double),
                    ("frontangle", ctypes.c_double), ("backangle", ctypes.c_double),
                    ("orientation", ctypes.c_int)]

    for i in range(100):
        lib._Z12tooldata_put16CANON_TOOL_TABLEi(
            _Tool(i if i else -1, i, (ctypes.c_double * 9)(), 0.0, 0.0, 0.0, 0), i)
    lib._Z23tooldata_last_index_seti(99)


_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)")


def _spindle_words(line):
    """The S and M words of source ``line`` as ``[(letter, value), ...]`` (letters 'm', 's'),
    ``None`` when one's value is not a plain number (``S#1``, ``M[3]``): only the interpreter
    knows it; a call (``o1 call``, ``M98``) ``None`` too: the lines it runs may set it. Other
    O-word lines and M99 set no spindle. Comments are ``( )`` and ``;``."""
    text = re.sub(r"\([^)]*\)?", "", line.split(";", 1)[0]).lower().translate(_BLANKS)
    start = re.match(r"/?(?:n\d+(?:\.\d+)?)?(?:(o(?:<[^>]*>|\d*)call)|o|m0*99(?![\d.])"
                     r"|(m0*98(?![\d.])))", text)
    if start:
        return None if start.group(1) or start.group(2) else []
    text = re.sub(r"#<[^>]*>", "#", text)
    out, depth = [], 0
    for i, c in enumerate(text):
        depth += (c == "[") - (c == "]")
        if depth or c not in "ms" or (i and text[i - 1].isalpha()):
            continue  # (a word's letter stands outside brackets, after no other letter)
        m = _NUMBER.match(text, i + 1)
        if not m or m.end() < len(text) and text[m.end()] not in "abcdefghijklmnopqrstuvwxyz#":
            return None
        out.append((c, float(m.group(0))))
    return out


_M61 = re.compile(r"(?<![a-z])m0*61(?![\d.])")
_UNITS = re.compile(r"(?<![a-z])g0*2([01])(?![\d.])")


def _units_word(line):
    """``True`` (G20, inches) or ``False`` (G21, mm) when source ``line`` has a plain G20 or
    G21 word (it takes effect before the line's motion), else ``None``."""
    text = re.sub(r"\([^)]*\)?", "", line.split(";", 1)[0]).lower().translate(_BLANKS)
    m = _UNITS.findall(re.sub(r"#<[^>]*>", "#", text))
    return m[-1] == "0" if m else None
_Q = re.compile(r"(?<![a-z])q(\+?[0-9]+(?:\.0*)?)(?![0-9.#\[])")


def _m61_tool(line):
    """The tool an ``M61 Q`` on source ``line`` makes the loaded one (the module reports no
    canon call for M61, only for M6: its moves kept the tool before it), ``None`` where the
    line has no M61 or its Q is no plain number (only the interpreter knows it then)."""
    text = re.sub(r"\([^)]*\)?", "", line.split(";", 1)[0]).lower().translate(_BLANKS)
    text = re.sub(r"#<[^>]*>", "#", text)
    if not _M61.search(text):
        return None
    q = _Q.search(text)
    return int(float(q.group(1))) if q else None


def _after(spindle, words):
    """The spindle ``(M code, speed)`` after a line's ``words`` (_spindle_words), in LinuxCNC's
    order: S, the tool change (M6 stops the spindle), then M3/M4/M5 (M19, an orientation,
    leaves it stopped: the interpreter reports M5 after it)."""
    code, speed = spindle
    for letter, v in words:
        if letter == "s":
            speed = v
    ms = [v for letter, v in words if letter == "m"]
    if 6 in ms:
        code = 5
    for v in ms:
        if v in (3, 4, 5):
            code = int(v)
        elif v == 19:
            code = 5
    return code, speed


def _rpm(spindle):
    code, speed = spindle
    return speed if code in (3, 4) else 0.0


class _Canon:
    def __init__(self, param_file, deadline):
        self.parameter_file = param_file
        self.deadline = deadline
        self.moves = []
        self.messages = []  # [line, text] of each MESSAGE call
        self.line = 0
        self.plane = 1
        self.g5x = [0.0] * 3
        self.g92 = [0.0] * 3
        self.rot = 0.0
        self.tlo = [0.0] * 3  # the tool length offset: the controlled point is the tip plus it
        self.ctrl = None  # the controlled point after the last move, mm
        self.mzero = [0.0] * 3  # the output shift: machine origin in the G54 frame, mm
        self.feed = 0.0  # mm/min (set_feed_rate: inch/min, as the module converts lengths)
        # G95 (feed per revolution): F is mm per revolution, a move's mm/min F times its spindle
        # speed; the interpreter says the mode only as a comment (comment())
        self.per_rev = False
        self.rev_feed: dict[int, float] = {}  # index of a G95 move -> its mm per revolution
        self.tool = 0  # the loaded tool (change_tool: M6)
        self.diameters: dict[int, float] = {}  # the user's tools by number, mm (get_tool)
        # the spindle: the interpreter's state reaches Python only through next_line, called
        # at a line's first canon call with the state as it was after the last block the
        # interpreter finished, so before the line's own S and M3/M4/M5/M6/M19, which take
        # effect before its motion. A move's spindle is that state with its own line's words
        # applied (_spindle_words). Only where a word's value is an expression ("S#1") is the
        # state read at the next line's first call, when that line comes later in the file and
        # no line between sets the spindle or calls a subroutine, else the state before the
        # line (a move line with an expression S, repeated by a loop, takes the value after
        # the loop's last pass for every pass). (It
        # waited for the next reported line every time and took it only after blank lines:
        # after a move line with 'S1000 M3' followed by o-word lines, a loop or an 'M5' alone,
        # which LinuxCNC does not report, its moves cut with the spindle off.)
        self.spindle = (0, 0.0)  # (M code 3/4/5, speed) at the last next_line
        self.rpm = 0.0
        self.pending = None  # (line, index of its first move) awaiting the state after it
        self.words: dict[int, list | None] = {}  # line -> its spindle words, None: not known
        self.m61: dict[int, int] = {}  # line -> the tool its M61 Q loads (_m61_tool)
        # the G20/G21 mode of a line's moves: the state before the line (next_line's, after the
        # last block finished, reported or not) unless the line's own G20/G21 word changes it
        self.inch = False
        self.units: dict[int, bool] = {}  # line -> its own G20 (True) / G21 (False) word
        self.message_at = []  # the interpreter's standard output's length at each message
        self.printed_at = lambda: 0  # that length now (_run sets it)

    def __getattr__(self, name):  # every other canon call has no effect on the moves
        if name.startswith("__"):
            raise AttributeError(name)
        return lambda *a: None

    def next_line(self, st):
        self.spindle = (st.spindle, float(st.speed))  # st.spindle: its M code
        rpm = _rpm(self.spindle)
        if self.pending is not None and st.sequence_number > self.pending[0] and all(
                k not in self.words for k in range(self.pending[0] + 1, st.sequence_number)):
            for k, m in enumerate(self.moves[self.pending[1]:], self.pending[1]):
                m[7] = rpm
                if k in self.rev_feed:
                    m[6] = self.rev_feed[k] * rpm
        self.pending = None
        self.line = st.sequence_number
        self.inch = self.units.get(self.line, st.gcodes[5] == 200)  # 200: G20, 210: G21
        if self.line in self.m61:  # M61 Q: the tool the line says is loaded (before its moves)
            self.tool = self.m61[self.line]
        words = self.words.get(self.line, [])
        self.rpm = rpm if words is None else _rpm(_after(self.spindle, words))
        if words is None:
            self.pending = (self.line, len(self.moves))

    def message(self, text):  # (MSG,...) and (DEBUG,...): what the operator's screen shows
        self.messages.append([self.line, text])
        # where the PRINT texts stand then: the order the two came in (_said_order)
        self.message_at.append(self.printed_at())

    def set_feed_rate(self, rate):
        self.feed = rate * MM

    def change_tool(self, tool):
        self.tool = int(tool)

    def comment(self, text):
        # how LinuxCNC's interpreter reports G93/G94/G95 ('interpreter: feed mode set to units
        # per revolution'); a G95 feed read as mm/min made a 100 mm cut at F0.1 S10000 take
        # 16.7 hours
        if text.startswith("interpreter: feed mode set to "):
            self.per_rev = text.endswith("per revolution")

    def _append(self, move):
        feed = self.feed
        if self.per_rev:
            self.rev_feed[len(self.moves)] = feed
            feed *= self.rpm
        self.moves.append(move + [feed, self.rpm, self.tool, self.inch])

    def get_external_angular_units(self):
        return 1.0

    def get_external_length_units(self):
        return 1.0  # a metric machine (LinuxCNC's TRAJ LINEAR_UNITS = mm): parameters in mm

    def get_axis_mask(self):
        return 7

    def get_block_delete(self):
        return 0

    def check_abort(self):
        return time.time() > self.deadline

    def get_tool(self, n):
        # pocket 0: the loaded tool's entry (change_tool, M6), read again after each change
        number = self.tool if n == 0 else n
        return (number,) + (0.0,) * 9 + (self.diameters.get(number, 0.0), 0.0, 0.0, 0)

    def set_g5x_offset(self, index, x, y, z, *rest):
        self.g5x = [x * MM, y * MM, z * MM]

    def set_g92_offset(self, x, y, z, *rest):
        self.g92 = [x * MM, y * MM, z * MM]

    def set_xy_rotation(self, theta):
        self.rot = theta

    def tool_offset(self, x, y, z, *rest):
        self.tlo = [x * MM, y * MM, z * MM]

    def set_plane(self, plane):
        self.plane = plane

    def _mach(self, p):
        return [v * MM + a + b + m for v, a, b, m in zip(p, self.g5x, self.g92, self.mzero)]

    def _straight(self, kind, p):
        end = self._mach(p)
        ctrl = [e + t for e, t in zip(end, self.tlo)]
        if self.ctrl is not None and max(abs(a - b) for a, b in zip(ctrl, self.ctrl)) < 1e-9:
            # the spindle stands: no motion. LinuxCNC emits such moves, and after a tool
            # length offset change (G28's intermediate point, say) the tip they report has
            # jumped by the change, a move that never happens
            return
        self.ctrl = ctrl
        self._append([kind, self.line, end, None, 0, 17])

    def straight_traverse(self, x, y, z, *rest):
        self._straight(0, (x, y, z))

    def straight_feed(self, x, y, z, *rest):
        self._straight(1, (x, y, z))

    def arc_feed(self, e1, e2, c1, c2, rot, en, *rest):
        a1, a2, an = _AXES[self.plane]
        end = [0.0] * 3
        end[a1], end[a2], end[an] = e1, e2, en
        end = self._mach(end)
        off = [a + b + m for a, b, m in zip(self.g5x, self.g92, self.mzero)]
        centre = [c1 * MM + off[a1], c2 * MM + off[a2]]
        self.ctrl = [e + t for e, t in zip(end, self.tlo)]
        self._append([2, self.line, end, centre, int(rot), _PLANE[self.plane]])

    def rigid_tap(self, x, y, z, *rest):
        self._straight(1, (x, y, z))


def main():
    here = os.path.dirname(os.path.abspath(__file__))  # woodcam's own gcode.py lives here
    sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != here]
    job = json.load(sys.stdin)
    result_fd = os.dup(1)
    os.dup2(2, 1)  # the interpreter prints debugging lines to stdout: send them to stderr
    work = tempfile.mkdtemp(prefix="woodcam-lcnc-")
    # run in the scratch folder: the interpreter looks for an 'o<name> call' it does not find
    # in the file as name.ngc in the working folder (no PROGRAM_PREFIX or SUBROUTINE_PATH here),
    # so the folder woodcam was started from gave the program its subroutines (a stale file of
    # that name there was cut); now none, as woodcam's interpreter, which reads one file
    os.chdir(work)
    try:  # the scratch folder (tool map, ini, parameter files) goes whatever happens
        _run(job, work, result_fd)
    finally:
        os.chdir("/")
        shutil.rmtree(work, ignore_errors=True)


def _mark_prints(data):
    """Program ``data`` (bytes) with each ``(PRINT,`` comment's text led by its line number
    between ``\\x01`` and ``\\x02`` (lines numbered at ``\\n``, as LinuxCNC does): the interpreter
    writes a PRINT's text, parameters put in, to its standard output and nothing says which line
    it ran; with the mark the text tells (:func:`_printed`). Returns ``(data, long)``, ``long``
    the lines left unmarked, the mark would make them longer than LinuxCNC reads (MAX_LINE),
    each with the patterns of the texts its PRINT comments can write (:func:`_print_pattern`)."""
    lines = data.split(b"\n")
    long = {}
    for i, line in enumerate(lines):
        if b"(" in line and _PRINT.search(line):
            marked = _PRINT.sub(lambda m: b"(" + m.group(1) + b"\x01%d\x02" % (i + 1), line)
            if len(marked) > MAX_LINE:
                long[i + 1] = [_print_pattern(line[m.end():].split(b")", 1)[0])
                               for m in _PRINT.finditer(line)]
            else:
                lines[i] = marked
        # (a print, comment LinuxCNC does not print, one not last on its line or after a ';',
        # prints nothing marked either)
    return b"\n".join(lines), long


#: a parameter's value in a PRINT text: C's %lf, or LinuxCNC's ###### for none
_VALUE = r"(?:-?[0-9]+\.[0-9]{6}|-?inf|-?nan|#+)"


def _print_pattern(text):
    """The pattern of what a ``(PRINT,`` comment of text ``text`` (bytes, after the comma)
    writes: its text with each ``#n`` and ``#<name>`` any value (as LinuxCNC 2.9 puts them in:
    woodcam's interpreter's ``Interpreter._expand`` says how); an unfinished ``#<`` ends in
    anything (LinuxCNC shows left-over text there)."""
    text = text.decode(errors="replace")
    out, i, n = [], 0, len(text)
    while True:
        j = text.find("#", i)
        if j < 0:
            out.append(re.escape(text[i:]))
            break
        out.append(re.escape(text[i:j]))
        i = j + 1
        if i < n and text[i].isdigit():
            while i < n and text[i].isdigit():
                i += 1
            out.append(_VALUE)
        elif i < n and text[i] == "<" and ">" in text[i:]:
            i = text.index(">", i) + 1
            out.append(_VALUE)
        elif i < n and text[i] != "<":
            out.append("#")
        else:
            out.append(".*")
            break
    return re.compile("".join(out), re.S)


def _printed(data, long):
    """The ``[line, text]`` of each PRINT in ``data`` (bytes), the interpreter's standard
    output of a program marked by :func:`_mark_prints`, the offset in ``data`` where each ends,
    and ``[[index, lines], ...]``, the texts whose line is not known. ``long``: the lines left
    unmarked, whose texts come unmarked: given the one line whose texts' patterns match, else
    the first of those that do (or of them all), and listed with those lines as not known. Any
    other line goes to stderr, as before."""
    out, ends, unknown, at = [], [], [], 0
    for raw in data.split(b"\n")[:-1]:
        at += len(raw) + 1
        line = raw.decode(errors="replace")
        m = _MARKED.match(line)
        if m:
            out.append([int(m.group(1)), m.group(2)])
        elif long:
            lines = [no for no, patterns in long.items()
                     if any(p.fullmatch(line) for p in patterns)] if len(long) > 1 else list(long)
            if len(lines) != 1:
                unknown.append([len(out), lines or list(long)])
            out.append([(lines or list(long))[0], line])
        else:
            sys.stderr.write(line + "\n")
            continue
        ends.append(at)
    return out, ends, unknown


def _said_order(message_at, printed_ends):
    """The messages (0) and PRINT texts (1) in the order the program said them: a PRINT text
    that ended in the standard output before a message was said (``message_at``, the output's
    length then) came before it; each list of texts keeps its own order."""
    order, k = [], 0
    for at in message_at:
        while k < len(printed_ends) and printed_ends[k] <= at:
            order.append(1)
            k += 1
        order.append(0)
    return order + [1] * (len(printed_ends) - k)


def _run(job, work, result_fd):
    import gcode  # after main() took woodcam's own gcode.py off the path

    _tool_table(work)
    ini = os.path.join(work, "sim.ini")
    var = os.path.join(work, "sim.var")
    with open(ini, "w") as f:
        f.write("[RS274NGC]\nPARAMETER_FILE = sim.var\n[TRAJ]\nLINEAR_UNITS = mm\n"
                "SPINDLES = 1\n")
    os.environ["INI_FILE_NAME"] = ini
    # the interpreter's standard output: the PRINT texts (_printed), read after each file
    said = os.path.join(work, "stdout.txt")
    fd = os.open(said, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    os.dup2(fd, 1)
    os.close(fd)
    libc, said_at = ctypes.CDLL(None), 0
    diameters = {int(k): float(v) for k, v in (job.get("tool_diameters_mm") or {}).items()}
    mzero = [float(v) for v in job.get("machine_zero_mm") or (0.0, 0.0, 0.0)]
    # the start in machine coordinates: G54 frame minus the machine origin's place in it
    sx, sy, sz = (v - m for v, m in zip(job["start_mm"], mzero))
    out = []
    for path in job["files"]:
        with open(var, "w") as f:  # G28/G30 homes at the start position, as woodcam does
            for base in (5161, 5181):  # (the parameter file holds the machine's units, mm)
                for i, v in enumerate((sx, sy, sz)):
                    f.write(f"{base + i}\t{v:.15f}\n")
            f.write("5220\t1.000000\n")  # (LinuxCNC reads the numbers in increasing order)
            for i, m in enumerate(mzero):  # G54 offset: the G54 origin in machine coordinates
                f.write(f"{5221 + i}\t{-m:.15f}\n")
        canon = _Canon(var, time.time() + job.get("timeout_s", 10.0))
        canon.mzero = mzero
        canon.diameters = diameters
        canon.printed_at = lambda: (libc.fflush(None), os.lseek(1, 0, os.SEEK_CUR))[1] - said_at
        with open(path, newline="", errors="replace") as f:  # numbered as LinuxCNC: at '\n' only
            lines = f.read().split("\n")
        with open(path, "rb") as f:
            raw = f.read()
        data, long = _mark_prints(raw)
        run = path
        if data != raw:  # a PRINT comment: run the marked copy
            run = os.path.join(work, "program.ngc")
            with open(run, "wb") as f:
                f.write(data)
        canon.words = {no: w for no, line in enumerate(lines, 1) if "m" in line.lower()
                       or "s" in line.lower() for w in [_spindle_words(line)] if w != []}
        canon.m61 = {no: t for no, line in enumerate(lines, 1) if "61" in line
                     for t in [_m61_tool(line)] if t is not None}
        canon.units = {no: u for no, line in enumerate(lines, 1) if "2" in line
                       for u in [_units_word(line)] if u is not None}
        # G49: the interpreter keeps a G43.1 tool length offset from one file to the next;
        # G80: the G0 that places the start must not be the program's motion mode (LinuxCNC
        # starts in G80: a bare "X10" first is refused, and was read as a G0 here)
        init = ["G21", "G90", "G49", f"G53 G0 X{sx:.12f} Y{sy:.12f} Z{sz:.12f}", "G80"]
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            result, seq = gcode.parse(run, canon, init, "")
            err = [seq, gcode.strerror(result)] if result > gcode.MIN_ERROR else None
        except KeyboardInterrupt:  # check_abort() said the time is up
            result, err = -2, [canon.line, "aborted: over the time limit"]
        except Exception as e:  # noqa: BLE001 - LinuxCNC raises plain RuntimeError
            result, err = -1, [0, f"{type(e).__name__}: {e}"]
        moves = [m for m in canon.moves if m[1] > 0]  # line 0: the init codes
        libc.fflush(None)  # C's stdout, a file: buffered
        with open(said, "rb") as f:
            f.seek(said_at)
            text = f.read()
            said_at = f.tell()
        printed, ends, unknown = _printed(text, long)
        out.append({"moves": moves, "messages": canon.messages, "printed": printed,
                    "said_order": _said_order(canon.message_at, ends),
                    "printed_unplaced": unknown, "error": err,
                    "result": result,
                    "seconds": time.perf_counter() - t0, "cpu_seconds": time.process_time() - c0})
    with os.fdopen(result_fd, "w") as f:
        json.dump(out, f)


if __name__ == "__main__":
    main()
