"""Refuse a .geo file that would do more than describe geometry, before gmsh ever reads it.

Cases are shared: opening one must not run a program, write or delete a file, or read one from
outside its case folder. Gmsh's .geo language can do all of these (gmsh 4.8.4, Parser/Gmsh.y and
Gmsh.l, the grammar gmsh itself is built from), so every file gmsh would read for a case is scanned
here first: the .geo, every file it Includes or Merges (recursively, confined to the case folder),
and the `<file>.opt` that gmsh merges by itself after reading `<file>` (Common/OpenFile.cpp).

The scan works on tokens, as gmsh's lexer does: `//` and `/* */` comments and "…" / '…' strings are
recognised first (gmsh has no escapes in strings), so a comment or a string that mentions
SystemCall is fine, and only identifiers can trigger a rule. gmsh dispatches a command on an
identifier (`SystemCall "…";` is `String__Index StringExpr ;`), and the one way to build that
identifier from strings is StringToName[…] / S2N[…], which is refused; `name~{i}` only appends
`_<i>`. Macro/Call with a computed name are allowed: they can only run a function whose body is in
a file scanned here. Include/Merge take a string literal only, so the path that gmsh opens is the
path checked.

The guard must see the tokens gmsh sees, so it also refuses what would make gmsh's lexer part from
this one (gmsh 4.8.4 Parser/Gmsh.l, each checked by running gmsh 4.8.4 on a .geo that shows it):
- a string of 1023 characters or more: gmsh keeps at most 1023 in a char[1024]; past them it says
  "String too long", drops one character and reads the rest of the string as commands;
- a NUL byte: gmsh ends a string, a comment or the file there;
- in a string, `//`, `/*` or the words If, Else, ElseIf, EndIf: gmsh skips the untaken branch of an
  `If` character by character (skipTest), honouring comments but not strings, and goes on at the
  first Else/EndIf it meets, even one inside a string, so the rest of that string would run;
- in an identifier, If/Else/EndIf after a digit (`x1EndIf`): skipTest takes a digit for a word
  boundary and would go on in the middle of the identifier;
- a comment opener or a quote that gmsh's skipping drops: while it skips an If branch, a For loop
  or a Function body, gmsh reads six characters at each E, I, F or R that starts a word, and when
  they are not its keyword it pushes back only four, losing the character after the letter; after
  an `If` or a `For` it pushes back none. ` E/* EndIf … */` then hides nothing from the guard but
  the comment from gmsh, which goes on at the EndIf inside it (tried: the command ran).
Every gmsh that reads a case's .geo also runs in a sandbox (preprocess/sandbox.py), so that a
construct this guard does not know of still cannot run a program or write outside its output.
"""
from __future__ import annotations

import os
import re

from .errors import PreprocessError

FIX = "a case's .geo may only describe geometry and mesh sizes; remove it"

# Identifiers that act on the system or stop gmsh, whatever follows them (gmsh 4.8.4 Gmsh.y).
FORBIDDEN = {
    "SystemCall": "runs a shell command",
    "System": "runs a shell command",
    "NonBlockingSystemCall": "runs a shell command",
    "OnelabRun": "runs an external program (a ONELAB client)",
    "OnelabAction": "talks to ONELAB clients (external programs)",
    "CreateDir": "creates a folder",
    "Print": "writes an image file",
    "Save": "writes a file",
    "SendToServer": "sends data to a ONELAB server",
    "Sleep": "pauses gmsh",
    "Exit": "ends gmsh before the mesh is written",
    "Abort": "ends the parse before the mesh is made",
    "StringToName": "turns a string into a command or a name, so a forbidden command could be spelt in pieces",
    "S2N": "turns a string into a command or a name, so a forbidden command could be spelt in pieces",
    "Plugin": "runs a gmsh plugin (some write or read files)",
    # Not in gmsh 4.8; refused in advance should a later gmsh add file commands under these names.
    "DeleteFile": "deletes a file",
    "RenameFile": "renames a file",
    "CreateFile": "writes a file",
}

# Commands whose argument is a file that gmsh reads: a string literal, inside the case folder.
READS_FILE = {"Include", "Merge", "MergeWithBoundingBox", "ShapeFromFile", "ListFromFile"}

# Options that name a program to launch or a file to write (gmsh 4.8.4 Common/DefaultOptions.h).
# Solver.* are the ONELAB clients' executables and remote logins: the whole category is refused.
OPTION_RISK = re.compile(r"(FileName|Command|Executable\d*|TextEditor|WebBrowser|Interpreter|"
                         r"RemoteLogin\d*|SaveOptions|SaveSession|Socket.*)$")

# Files gmsh reads as data, not as .geo commands (everything else it would parse as .geo).
DATA_EXTENSIONS = {".msh", ".step", ".stp", ".brep", ".iges", ".igs", ".stl", ".unv", ".med", ".vtk"}

MAX_INCLUDE_DEPTH = 20
MAX_GEO_BYTES = 10 * 1024 * 1024
# gmsh 4.8.4 parsestring() cuts a string at 1023 characters (`char tmp[1024]`): refused from there.
GMSH_STRING_CUT = 1023
# What gmsh's skipTest (the untaken branch of an If) reacts to while it ignores strings.
# Anywhere in the string, whatever precedes: gmsh's "previous character" is stale after a dropped one.
SKIP_TEST_IN_STRING = re.compile(r"//|/\*|EndIf|Else|If")
SKIP_TEST_IN_IDENT = re.compile(r"[0-9](?:EndIf|Else|If)")

TOKEN = re.compile(r"""
    (?P<space>[ \t\r\f]+) | (?P<newline>\n)
  | (?P<line_comment>//[^\n]*)
  | (?P<block_comment>/\*)
  | (?P<string>"[^"]*"|'[^']*')
  | (?P<open_string>["'])
  | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[Ee][-+]?\d+)?)
  | (?P<ident>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<punct>>>|>=|<<|<=|==|!=|&&|\|\||\+\+|--|::|\.\.\.|[-+*/=]=|.)
""", re.VERBOSE)


def tokens(text: str, path: str):
    """(kind, value, line) for every token outside comments: kind is ident, string, number or punct."""
    line, at = 1, 0
    while at < len(text):
        m = TOKEN.match(text, at)
        kind = m.lastgroup
        if kind == "block_comment":
            end = text.find("*/", m.end())
            if end < 0:
                raise PreprocessError(f"{path}:{line}: a /* comment is never closed; close it with */")
            line += text.count("\n", at, end)
            at = end + 2
            continue
        if kind == "open_string":
            raise PreprocessError(f"{path}:{line}: a string is never closed; close it with {m.group()}")
        if kind == "newline":
            line += 1
        elif kind == "string":
            _check_string(m.group()[1:-1], path, line)
            yield kind, m.group()[1:-1], line
            line += m.group().count("\n")
        elif kind in ("ident", "number", "punct"):
            yield kind, m.group(), line
        at = m.end()


def _skip_hazard(text: str) -> int | None:
    """The offset of a character gmsh's skip()/skipTest() would drop unseen that opens a comment or a
    string (see the module's docstring), or None. Over-approximates where gmsh would start a
    candidate word: after a non-letter, and where skipping resumes after a dropped character."""
    def word_start(k: int) -> bool:
        return k == 0 or not (text[k - 1].isalpha() or text[k - 1] == "_")

    candidates = [k for k, c in enumerate(text) if c in "EIFR" and word_start(k)]
    seen = set(candidates)
    while candidates:
        k = candidates.pop()
        swallowed = [k + 1]                          # a word that is not the keyword: one lost
        resume = [k + 2]
        if text.startswith("If", k) and not text[k + 2:k + 3].isalpha():
            swallowed, resume = range(k + 2, k + 6), [k + 6]   # nested If: four lost
        elif text.startswith("For", k) and not text[k + 3:k + 4].isalpha():
            swallowed, resume = range(k + 3, k + 6), [k + 6]   # nested For: three lost
        for j in swallowed:
            if j < len(text) and (text[j] in "\"'" or text.startswith(("//", "/*"), j)):
                return j
        for j in resume:   # gmsh goes on there with the old previous character: a word start
            if j < len(text) and text[j] in "EIFR" and j not in seen:
                seen.add(j)
                candidates.append(j)
    return None


def _check_string(value: str, path: str, line: int):
    """A string literal that gmsh would not read as one string (see the module's docstring)."""
    if len(value) >= GMSH_STRING_CUT:
        raise PreprocessError(f"{path}:{line}: a string of {len(value)} characters; gmsh cuts strings at "
                              f"{GMSH_STRING_CUT} characters and reads the rest as commands: keep it shorter")
    found = SKIP_TEST_IN_STRING.search(value)
    if found:
        raise PreprocessError(f"{path}:{line}: the string \"{value[:40]}\" holds '{found.group()}', which gmsh "
                              "takes for a comment or for the end of an If branch even inside a string, so "
                              "the rest of it could run as commands: reword the string")


def check_geo(geo_path: str, case_dir: str | None = None) -> list[str]:
    """Raise PreprocessError naming the file, the line and what to do if `geo_path` or any file it
    makes gmsh read could run a command, write a file or read outside `case_dir` (default: the
    .geo's folder). Returns the files scanned."""
    case_dir = os.path.realpath(case_dir or os.path.dirname(os.path.abspath(geo_path)))
    scanned: list[str] = []
    _scan(geo_path, case_dir, scanned, depth=0)
    return scanned


def _scan(path: str, case_dir: str, scanned: list, depth: int):
    real = os.path.realpath(path)
    if real in scanned:
        return  # an Include cycle: gmsh would loop, the .geo is wrong, but nothing new to check
    # The .geo itself and the .opt gmsh merges by itself: a symbolic link out of the case folder
    # (to /etc/shadow) had gmsh print the file's first line in its syntax error.
    check_inside(path, case_dir)
    scanned.append(real)
    try:
        if os.path.getsize(path) > MAX_GEO_BYTES:
            raise PreprocessError(f"{path}: larger than {MAX_GEO_BYTES >> 20} MB; a .geo is a short script")
        with open(path, "rb") as stream:
            raw = stream.read()
    except OSError as err:
        raise PreprocessError(f"{path}: cannot read: {err.strerror}") from None
    if b"\0" in raw:
        line = raw[:raw.index(b"\0")].count(b"\n") + 1
        raise PreprocessError(f"{path}:{line}: a NUL byte, which ends a string or a comment early for gmsh; "
                              "a .geo is a text file: remove it")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        line = raw[:err.start].count(b"\n") + 1
        raise PreprocessError(f"{path}:{line}: not UTF-8 text; a .geo is a text file") from None
    hazard = _skip_hazard(text)
    if hazard is not None:
        line = text.count("\n", 0, hazard) + 1
        shown = text[max(0, hazard - 5):hazard + 1].split("\n")[-1].strip()
        raise PreprocessError(f"{path}:{line}: '{shown}': gmsh, skipping an If branch, a "
                              f"For loop or a Function body, would not see the {text[hazard]!r} after the E, I, F or "
                              "R before it and would read what follows differently: put a space between them")
    found = list(tokens(text, path))
    for k, (kind, value, line) in enumerate(found):
        if kind != "ident":
            continue
        where = f"{path}:{line}"
        if SKIP_TEST_IN_IDENT.search(value):
            raise PreprocessError(f"{where}: the name '{value}' holds If/Else/EndIf after a digit, where gmsh "
                                  "would end a skipped If branch in the middle of the name: rename it")
        # Where gmsh goes on in the middle of a name, it reads the digits as a number and the rest
        # as a name of its own: a command after digits could hide in a longer name.
        hidden = [word for word in FORBIDDEN if re.search(rf"[0-9]{word}", value)]
        if hidden:
            raise PreprocessError(f"{where}: the name '{value}' holds '{hidden[0]}' after a digit, which gmsh could "
                                  f"read as a command of its own; {FIX}")
        if value in FORBIDDEN:
            raise PreprocessError(f"{where}: '{value}' {FORBIDDEN[value]}; {FIX}")
        if value == "Printf" and _printf_redirects(found, k):
            raise PreprocessError(f"{where}: Printf(…) > \"file\" writes a file; {FIX}, or print to the "
                                  f"terminal with Printf(…); alone")
        if k + 2 < len(found) and found[k + 1][1] == "." and found[k + 2][0] == "ident":
            option = found[k + 2][1]
            if value == "Solver" or OPTION_RISK.search(option):
                raise PreprocessError(f"{where}: the option {value}.{option} names a program to run or a "
                                      f"file to write; {FIX}")
        if value in READS_FILE:
            target = _literal_argument(found, k)
            if target is None:
                raise PreprocessError(f"{where}: {value} needs a plain \"file name\" (a string literal, so "
                                      f"that the file can be checked); write the name out")
            _check_read(value, target, path, line, case_dir, scanned, depth)
    opt = path + ".opt"
    if os.path.exists(opt):  # gmsh merges <file>.opt after <file>, as .geo commands
        _scan(opt, case_dir, scanned, depth + 1)


def check_inside(path: str, case_dir: str):
    """PreprocessError unless `path`, its symbolic links followed, is a regular file inside `case_dir`."""
    real = os.path.realpath(path)
    case_dir = os.path.realpath(case_dir)
    if os.path.commonpath([real, case_dir]) != case_dir:
        raise PreprocessError(f"{path}: leads outside the case folder {case_dir} (a symbolic link to {real}); "
                              "a case reads only its own files: copy the file into the case folder")
    if not os.path.isfile(real):
        from common.regular_file import kind_of

        what = "does not exist" if not os.path.exists(real) else f"{kind_of(os.stat(real).st_mode)}, not a regular file"
        raise PreprocessError(f"{path}: {what}; a case input must be a regular file in {case_dir}")


def _printf_redirects(found, k) -> bool:
    """Printf ( … ) followed by > or >> before the end of the statement: gmsh's SendToFile."""
    depth = 0
    for kind, value, _ in found[k + 1:]:
        if kind != "punct":
            continue
        if value in "([{":
            depth += 1
        elif value in ")]}":
            depth -= 1
        elif value == ";" and depth <= 0:
            return False
        elif value in (">", ">>") and depth == 0:
            return True
    return False


def _literal_argument(found, k):
    """The file name of Include "f"; / Merge "f"; / ShapeFromFile("f") / ListFromFile["f"], when it is
    one string literal followed by the end of the argument; else None."""
    rest = found[k + 1:k + 4]
    if len(rest) >= 2 and rest[0][0] == "string" and rest[1][1] == ";":
        return rest[0][1]
    if len(rest) == 3 and rest[0][1] in "([" and rest[1][0] == "string" and rest[2][1] in ")]":
        return rest[1][1]
    return None


def _check_read(command, target, path, line, case_dir, scanned, depth):
    where = f"{path}:{line}"
    parts = re.split(r"[/\\]", target)
    if os.path.isabs(target) or target.startswith("~") or ".." in parts:
        raise PreprocessError(f"{where}: {command} \"{target}\": a case reads only files inside its own "
                              f"folder; copy the file into {case_dir} and name it relative to {path}")
    resolved = os.path.join(os.path.dirname(os.path.abspath(path)), target)
    real = os.path.realpath(resolved)
    if os.path.commonpath([real, case_dir]) != case_dir:
        raise PreprocessError(f"{where}: {command} \"{target}\" leads outside the case folder {case_dir} "
                              f"(a symbolic link?); copy the file into the case folder")
    if not os.path.isfile(real):
        raise PreprocessError(f"{where}: {command} \"{target}\": no such file in the case folder")
    if os.path.splitext(real)[1].lower() in DATA_EXTENSIONS:
        return
    if depth >= MAX_INCLUDE_DEPTH:
        raise PreprocessError(f"{where}: files included more than {MAX_INCLUDE_DEPTH} deep; include fewer")
    _scan(resolved, case_dir, scanned, depth + 1)


def geo_identifiers(geo_path: str) -> set[str]:
    """Every identifier of the .geo and of the files it Includes (after check_geo: those are the
    case's own files): a gmsh parameter of the case file that is none of them is ignored by gmsh
    (`-setnumber` on a name the .geo never reads), a mistake to report (issue 17, item 10)."""
    names: set[str] = set()
    for path in check_geo(geo_path):
        if not path.endswith(".geo"):
            continue
        with open(path, "rb") as stream:
            text = stream.read().decode("utf-8")
        names.update(value for kind, value, _ in tokens(text, path) if kind == "ident")
    return names


# A DefineConstant entry `NAME = {value, ... Name "Parameters/label [m]"}`: the label's unit says
# what the parameter is. gmsh itself takes any number, so `a: -0.005` meshed the same hole as 0.005
# and `lc: 0` made gmsh fall back to its default size (issue 17, item 10).
DEFINE_CONSTANT_ENTRY = re.compile(r"\b([A-Za-z_][A-Za-z0-9_]*)\s*=\s*\{[^{}]*?\bName\s*\"([^\"]*)\"", re.S)


def geo_lengths(geo_path: str) -> dict[str, str]:
    """The parameters that the .geo (and the files it Includes) label as lengths, "[m]" in their
    DefineConstant Name: name → the Name ("Parameters/mesh size [m]"). A length must be > 0."""
    lengths: dict[str, str] = {}
    for path in check_geo(geo_path):
        if not path.endswith(".geo"):
            continue
        with open(path, "rb") as stream:
            text = stream.read().decode("utf-8")
        for name, label in DEFINE_CONSTANT_ENTRY.findall(text):
            if "[m]" in label:
                lengths[name] = label
    return lengths
