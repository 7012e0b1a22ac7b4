"""What a scene's gmsh file may do: checked before gmsh reads it, then read in a child process
that is given a time limit.

gmsh takes a file in one of three ways (its MergeFile):

    CAD     by the extension (.brep, .step, .stp, .STEP, .STP): OpenCASCADE imports the shape
    mesh    by the first line ($MeshFormat, $Comments, $NOD, $ELM, $PTS, $PARA): a mesh
    script  anything else, whatever the file is called: gmsh's .geo language

and after merging a file F it merges F.opt, a script, where there is one. CAD files and meshes
are data. A script can run programs, write files and end the process, so every script gmsh
would parse (the file itself, F.opt, and what they Include or Merge) is read first as gmsh's
lexer reads it (comments and strings skipped, identifiers whole) and refused where it:

    runs a program              System, SystemCall, NonBlockingSystemCall, OnelabRun,
                                SendToServer, the field ExternalProcess
    ends or stalls the process  Exit, Abort, Sleep, GetValue, GetStringValue (asks the user)
    writes a file or folder     Save, Print, CreateDir, Printf(...) > file, Plugin(...)
    sets options other than     General, Solver, PostProcessing, View (and Print) options
      Geometry.* and Mesh.*
    builds a name from a string StringToName, S2N (a command spelled at run time)
    reads a file not named      the field Structured (a file name given as a string option);
      by a literal              Include, Merge, MergeWithBoundingBox, ShapeFromFile and
                                ListFromFile take a literal relative path inside the folder
                                of the scene's file, and what they name is checked the same way

A script may not hold NUL bytes or strings longer than gmsh's lexer keeps (1023 characters):
there gmsh and this check would read different tokens. What passes is bounded in time by the
child read (read_file): gmsh parses the file in a fresh process that is stopped after
READ_SECONDS; its result or its error comes back as an InputError naming geometry.file.
"""

import json
import re
import subprocess
import sys
from pathlib import Path

from shellform.errors import InputError

FIELD = "geometry.file"
READ_SECONDS = 60.0  # the longest gmsh may take to read a blank's file (a .geo that meshes itself, a large CAD file)
MAX_SCRIPT_BYTES = 10_000_000
MAX_STRING = 1022  # gmsh's lexer keeps 1023 characters of a string and reads the rest as code
CAD_SUFFIXES = (".brep", ".step", ".stp", ".STEP", ".STP")  # gmsh dispatches these by name, case and all
MESH_HEADERS = (b"$PTS", b"$NO", b"$PARA", b"$ELM", b"$MeshFormat", b"$Comments")
VIEW_HEADERS = (b"$PostFormat", b"$View")
MERGE_SUFFIXES = (".msh", ".geo", ".step", ".stp", ".brep")  # what a script may Merge (any case)

REFUSED = {
    **dict.fromkeys(("System", "SystemCall", "NonBlockingSystemCall", "OnelabRun", "SendToServer"),
                    "runs a program"),
    "ExternalProcess": "runs a program (a mesh-size field)",
    "Exit": "ends the process", "Abort": "stops gmsh's reading", "Sleep": "stalls the process",
    "GetValue": "asks the user for input", "GetStringValue": "asks the user for input",
    "Save": "writes a file", "Print": "writes a file", "CreateDir": "creates a folder",
    "Plugin": "runs a gmsh plugin (plugins write files)",
    **dict.fromkeys(("General", "Solver", "PostProcessing", "View"),
                    "sets gmsh options outside Geometry.* and Mesh.*"),
    "StringToName": "builds a name from a string", "S2N": "builds a name from a string",
    "Structured": "reads a file named by a string (a mesh-size field)",
}
FILE_COMMANDS = {  # command: (how gmsh reads the file it names, its syntax)
    "Include": ("script", "statement"), "Merge": ("merge", "statement"),
    "MergeWithBoundingBox": ("merge", "statement"),
    "ShapeFromFile": ("cad", "call"), "ListFromFile": ("data", "call"),
}

# gmsh's lexer (Gmsh.l): comments, strings in " or ', numbers, identifiers, single characters
_TOKEN = re.compile(r"""
    (?P<space>[ \t\n\r\f]+)
  | (?P<block>/\*.*?\*/)
  | (?P<open_block>/\*)
  | (?P<line>//[^\n]*)
  | (?P<string>"[^"]*"|'[^']*')
  | (?P<open_string>["'])
  | (?P<number>[0-9]+\.[0-9]*(?:[eE][-+]?[0-9]+)?|[0-9]*\.[0-9]+(?:[eE][-+]?[0-9]+)?|[0-9]+(?:[eE][-+]?[0-9]+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<other>.)
""", re.VERBOSE | re.DOTALL)


def reads_as(path: Path) -> str:
    """How gmsh's MergeFile takes this file: 'cad', 'mesh', 'view' or 'script'."""
    if path.suffix in CAD_SUFFIXES:
        return "cad"
    with open(path, "rb") as f:
        first = f.readline(255)
    if first.startswith(MESH_HEADERS):
        return "mesh"
    return "view" if first.startswith(VIEW_HEADERS) else "script"


def check(path) -> tuple:
    """Refuse (InputError naming geometry.file) a file whose reading by gmsh would reach outside
    the geometry; return the version of what gmsh reads: (path, mtime_ns, size) of each file."""
    path = Path(path)
    checker = _Checker(path.parent.resolve())
    checker.merge(path, str(path))
    return tuple(checker.stamps)


class _Checker:
    def __init__(self, root: Path):
        self.root, self.stamps, self.stack, self.done = root, [], [], set()

    def merge(self, path: Path, shown: str):
        """gmsh's MergeFile: the file by its kind, then its .opt sibling."""
        kind = reads_as(path)
        if kind == "view":
            raise InputError(FIELD, f"{shown} holds post-processing views, not a blank")
        if kind == "script":
            self.script(path, shown)
        else:
            self.stamp(path)
        opt = path.with_name(path.name + ".opt")
        if opt.is_file():
            self.merge(opt, f"{shown}.opt (gmsh merges it after {path.name})")

    def stamp(self, path: Path):
        st = path.stat()
        self.stamps.append((str(path.resolve()), st.st_mtime_ns, st.st_size))

    def script(self, path: Path, shown: str):
        key = path.resolve()
        if key in self.stack:
            raise InputError(FIELD, f"{shown} includes itself (through {' -> '.join(p.name for p in self.stack)})")
        if key in self.done:
            return
        self.stamp(path)
        if path.stat().st_size > MAX_SCRIPT_BYTES:
            raise InputError(FIELD, f"{shown}: a .geo script of more than {MAX_SCRIPT_BYTES:,} bytes is refused")
        data = path.read_bytes()
        if b"\0" in data:
            raise InputError(FIELD, f"{shown}: a .geo script must not hold NUL bytes")
        self.stack.append(key)
        tokens = list(_tokens(data.decode("latin-1"), shown))
        for i, (kind, text, line) in enumerate(tokens):
            if kind != "name":
                continue
            where = f"{shown}, line {line}"
            if text in REFUSED:
                raise InputError(FIELD, f"{where}: '{text}' {REFUSED[text]}; a blank's .geo file may not do that "
                                 "(docs/scenes.md, What a .geo file may do)")
            if text == "Printf" and _redirected(tokens, i):
                raise InputError(FIELD, f"{where}: 'Printf(...) >' writes a file; a blank's .geo file may not do that")
            if text in FILE_COMMANDS:
                how, syntax = FILE_COMMANDS[text]
                name = _literal_argument(tokens, i, syntax)
                if name is None:
                    raise InputError(FIELD, f"{where}: '{text}' must name its file by a literal string, "
                                     f"e.g. {text} \"part.geo\"")
                target = self.inside(path, name, f"{where}: {text} \"{name}\"")
                self.read(target, how, f"{name} ({text} in {shown})", f"{where}: {text} \"{name}\"")
        self.stack.pop()
        self.done.add(key)

    def inside(self, including: Path, name: str, where: str) -> Path:
        if not name or Path(name).is_absolute() or "\\" in name:
            raise InputError(FIELD, f"{where}: the file must be a relative path inside {self.root}")
        target = including.parent / name
        if not target.resolve().is_relative_to(self.root):
            raise InputError(FIELD, f"{where}: the file lies outside {self.root}")
        if not target.is_file():
            raise InputError(FIELD, f"{where}: no such file")
        return target

    def read(self, target: Path, how: str, shown: str, where: str):
        if how == "script":
            self.script(target, shown)
        elif how == "merge":
            if target.suffix.lower() not in MERGE_SUFFIXES:
                raise InputError(FIELD, f"{where}: a blank's .geo may merge only {', '.join(MERGE_SUFFIXES)} files")
            self.merge(target, shown)
        else:  # CAD shapes and lists of numbers are data
            self.stamp(target)


def _tokens(text: str, shown: str):
    line = 1
    for m in _TOKEN.finditer(text):
        kind = m.lastgroup
        if kind in ("open_block", "open_string"):
            raise InputError(FIELD, f"{shown}, line {line}: a {'comment' if kind == 'open_block' else 'string'} "
                             "is not closed")
        if kind == "string" and len(m.group()) - 2 > MAX_STRING:
            raise InputError(FIELD, f"{shown}, line {line}: a string longer than {MAX_STRING} characters "
                             "(gmsh would read its tail as code)")
        if kind not in ("space", "block", "line"):
            yield kind, m.group(), line
        line += m.group().count("\n")


def _literal_argument(tokens, i, syntax) -> str | None:
    """The literal file name of the command at tokens[i] (None: not a literal)."""
    nxt = [t[1] for t in tokens[i + 1:i + 4]]
    kinds = [t[0] for t in tokens[i + 1:i + 4]]
    if syntax == "statement" and len(nxt) >= 2 and kinds[0] == "string" and nxt[1] == ";":
        return nxt[0][1:-1]
    if syntax == "call" and len(nxt) == 3 and nxt[0] == "(" and kinds[1] == "string" and nxt[2] == ")":
        return nxt[1][1:-1]
    return None


def _redirected(tokens, i) -> bool:
    """Whether the Printf at tokens[i] sends its text to a file (Printf(...) > or >> file)."""
    depth = 0
    for j in range(i + 1, len(tokens)):
        text = tokens[j][1]
        if text == ";":
            return False
        depth += (text == "(") - (text == ")")
        if depth == 0 and text == ")":
            return j + 1 < len(tokens) and tokens[j + 1][1] == ">"
    return False


def read_file(path, options: dict) -> tuple[tuple[str, ...], int, tuple[float, float], float | None]:
    """(boundary groups, triangles in its mesh (0: none yet), bounding-box width and height, the
    median segment of its curves at the file's own mesh sizes (None where it holds a mesh)) of a
    checked gmsh file, read by gmsh with these options in a child process (gmsh_reader.py)
    stopped after READ_SECONDS."""
    script = Path(__file__).with_name("gmsh_reader.py")
    cmd = [sys.executable, "-P", str(script), str(path), json.dumps(options)]  # -P: not the script's folder on sys.path
    result = read_in_child(cmd, path, FIELD, _MARK, READ_SECONDS, "(a long loop, or a mesh made in the file?)")
    if result.get("empty"):
        raise InputError(FIELD, f"{path} holds no geometry and no mesh (an empty file?)")
    return tuple(result["groups"]), int(result["triangles"]), tuple(result["size"]), result.get("segment")


_MARK = "shellform-gmsh-read: "


def read_in_child(cmd: list, path, field: str, mark: str, seconds: float, slow: str = "") -> dict:
    """Run `cmd`, a child process in which gmsh reads `path` and prints one line, `mark` and
    JSON: its summary, or {"error": gmsh's message}. The child is stopped after `seconds`.
    Returns the summary; InputError naming `field` where the child overran (`slow`: a likely
    cause), stopped without its line, or gmsh could not read the file."""
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=seconds, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise InputError(field, f"gmsh did not finish reading {path} within {seconds:g} s" + (f" {slow}" if slow else "")) \
            from None
    lines = [ln for ln in done.stdout.splitlines() if ln.startswith(mark)]
    if not lines:
        tail = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
        raise InputError(field, f"gmsh stopped while reading {path} (exit status {done.returncode}): {tail[0]}")
    result = json.loads(lines[-1][len(mark):])
    if "error" in result:
        raise InputError(field, f"gmsh cannot read {path}: {result['error']}")
    return result
