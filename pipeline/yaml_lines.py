"""Load a case file (YAML) into plain Python objects while remembering the line of every key.

The loader is safe and bounded, because a case file comes from other people (issue 17, item 3):
- the file is a regular UTF-8 text file of at most MAX_BYTES (a binary file, /dev/zero, a FIFO or a
  directory is refused before it is parsed, and a FIFO without blocking: common/regular_file.py);
- nesting is at most MAX_DEPTH deep, and the tree, with every alias expanded, has at most
  MAX_NODES values (a "billion laughs" file of nested aliases fails at once instead of expanding
  10¹⁰ items), no alias may contain itself;
- a text value has at most MAX_SCALAR characters;
- a whole number is at most MAX_NUMBER in size, the largest double: every number of a case file
  becomes one (Python's float(), the solver's JSON reader), and a 400-digit integer ended in an
  OverflowError, a 5000-digit one in Python's int-string limit (4300 digits), both as tracebacks
  (issue 36, item 11);
- explicit tags (`!foo`, `!!python/object:…`) and merge keys (`<<`) are refused: a case file is
  plain data, and nothing in it may name a Python type;
- plain scalars are read with the YAML 1.2 core schema (https://yaml.org/spec/1.2.2/#1032-tag-resolution):
  `1e-3` is a number, `yes` and `2001-12-14` are text. The YAML 1.1 forms that a 1.1 reader takes
  for a different number (`5:00` = 300 in base 60, `012` = 10 in octal) are refused with the line.
PyYAML's composer keeps a source mark on every node; we walk the node tree ourselves, so that an
error about `time.safety_factor` can say "plate.yaml:14".
"""
from __future__ import annotations

import re
import sys

import yaml
from yaml.events import AliasEvent, CollectionStartEvent, ScalarEvent

from common.regular_file import NotRegularFile, read_regular

MAX_BYTES = 1 << 20      # 1 MiB: the shipped cases are below 3 kB
MAX_DEPTH = 64           # the schema nests 4 deep; a table of rows is 2 more
MAX_NODES = 100_000      # values after alias expansion (a time table of 10⁴ rows is 3·10⁴)
MAX_SCALAR = 10_000      # characters in one value
MAX_NUMBER = sys.float_info.max   # 1.8e308: the largest double
MAX_DIGITS = len(str(int(MAX_NUMBER)))   # 309: a longer decimal integer is larger still

# YAML 1.2 core schema, plain scalars only (quoted scalars are always text).
_NULL = re.compile(r"^(?:~|null|Null|NULL|)$")
_TRUE = re.compile(r"^(?:true|True|TRUE)$")
_FALSE = re.compile(r"^(?:false|False|FALSE)$")
_INT10 = re.compile(r"^[-+]?[0-9]+$")
_INT8 = re.compile(r"^0o[0-7]+$")
_INT16 = re.compile(r"^0x[0-9a-fA-F]+$")
_FLOAT = re.compile(r"^[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?$")
_INF = re.compile(r"^[-+]?\.(?:inf|Inf|INF)$")
_NAN = re.compile(r"^\.(?:nan|NaN|NAN)$")
# YAML 1.1 forms that a 1.1 reader (PyYAML's, and the one that wrote the issue) takes for another
# number than 1.2 does: refused, so that no reader can disagree about the value.
_SEXAGESIMAL = re.compile(r"^[-+]?[0-9][0-9_]*(?::[0-5]?[0-9])+(?:\.[0-9_]*)?$")
_OCTAL_11 = re.compile(r"^[-+]?0[0-9_]+$")

_MERGE_HINT = "write the keys out in full (an alias *name may stand for a whole value, not be merged)"


class CaseError(Exception):
    """A problem in a case file, with the file, the line and what to do in the message."""


def dotted(keypath: tuple) -> str:
    """("materials", "glass", "density") → "materials.glass.density"; list indices as [i]."""
    return ".".join(f"[{p}]" if isinstance(p, int) else str(p) for p in keypath).replace(".[", "[")


def _integer(text: str, digits: str, base: int, where: str):
    """A whole number no larger than MAX_NUMBER; the digit count is checked before int() so that
    Python's int-string limit (4300 decimal digits) is never reached."""
    too_long = base == 10 and len(digits.lstrip("0")) > MAX_DIGITS
    value = None if too_long else int(digits, base)
    if value is None or value > MAX_NUMBER:
        shown = text if len(text) <= 24 else f"{text[:12]}…{text[-6:]} ({len(text)} characters)"
        raise CaseError(f"{where}: the whole number {shown} is too large: a number in a case file is at "
                        f"most {MAX_NUMBER:.4g} (a double) and a count at most 2^53; write it in "
                        "exponent form (e.g. 1.0e+9) and check it for a typo")
    return -value if text.startswith("-") else value


def _core_scalar(text: str, where: str):
    """The value of a plain scalar under the YAML 1.2 core schema."""
    if _NULL.match(text):
        return None
    if _TRUE.match(text):
        return True
    if _FALSE.match(text):
        return False
    if _SEXAGESIMAL.match(text):
        raise CaseError(f"{where}: '{text}' is a base-60 number in YAML 1.1 and text in YAML 1.2; "
                        "write the plain number (e.g. 300 for 5:00), or quote it if it is text")
    if _OCTAL_11.match(text):
        raise CaseError(f"{where}: '{text}' starts with 0: YAML 1.1 reads it as octal, YAML 1.2 as "
                        f"decimal; write it without the leading 0 (or 0o… for octal)")
    if _INT10.match(text):
        return _integer(text, text.lstrip("+-"), 10, where)
    if _INT8.match(text):
        return _integer(text, text[2:], 8, where)
    if _INT16.match(text):
        return _integer(text, text[2:], 16, where)
    if _FLOAT.match(text):
        return float(text)
    if _INF.match(text):
        return float("-inf") if text.startswith("-") else float("inf")
    if _NAN.match(text):
        return float("nan")
    return text


class _BoundedLoader(yaml.SafeLoader):
    """PyYAML's parser and composer with a depth limit and no explicit tags.

    Only composition is used (never PyYAML's constructor): the walk below builds the values.
    """

    def __init__(self, stream, path: str):
        super().__init__(stream)
        self.path = path
        self.depth = 0

    def compose_node(self, parent, index):
        event = self.peek_event()
        where = f"{self.path}:{event.start_mark.line + 1}"
        if not isinstance(event, AliasEvent):
            tag = getattr(event, "tag", None)
            if isinstance(event, (ScalarEvent, CollectionStartEvent)) and tag is not None:
                raise CaseError(f"{where}: the tag '{tag}' is not allowed: a case file is plain "
                                "numbers, text, lists and keys; remove the tag")
        if isinstance(event, ScalarEvent) and len(event.value) > MAX_SCALAR:
            raise CaseError(f"{where}: a value of {len(event.value)} characters; a case file value "
                            f"has at most {MAX_SCALAR}: shorten it")
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                raise CaseError(f"{where}: nested more than {MAX_DEPTH} levels deep; a case file "
                                "nests a few levels (section, entry, table row): check the brackets")
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1


def _read_text(path: str) -> str:
    """The file's text, or a CaseError if it is not a small regular UTF-8 text file."""
    try:
        data = read_regular(path, MAX_BYTES)
    except NotRegularFile as err:
        raise CaseError(f"{err}; give the case's .yaml file") from None
    except OSError as err:
        raise CaseError(f"{path}: cannot read the case file: {err.strerror}") from None
    if len(data) > MAX_BYTES:
        raise CaseError(f"{path}: larger than {MAX_BYTES // 1024} kB; a case file is a few kB of "
                        "keys (long lists belong in the mesh or a table file): check it is the right file")
    nul = data.find(b"\0")
    if nul >= 0:
        line = data.count(b"\n", 0, nul) + 1
        raise CaseError(f"{path}:{line}: a NUL byte: this is a binary file, not a case file (YAML text)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        raise CaseError(f"{path}:{line}: not UTF-8 text (byte 0x{data[err.start]:02x}); save the case "
                        "file as UTF-8 YAML text") from None


def _compose(text: str, path: str):
    loader = None
    try:
        loader = _BoundedLoader(text, path)  # the reader checks every character here
        return loader.get_single_node()
    except yaml.reader.ReaderError as err:
        line = text.count("\n", 0, err.position) + 1
        raise CaseError(f"{path}:{line}: character #x{err.character:04x} is not allowed in "
                        "YAML text; remove it") from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else path
        problem = getattr(err, "problem", None) or str(err)
        context = getattr(err, "context", None)
        problem = f"{context}, {problem}" if context else problem
        raise CaseError(f"{where}: not valid YAML: {problem}") from None
    finally:
        if loader is not None:
            loader.dispose()


def load_with_lines(path: str):
    """Return (data, lines) where lines maps a key path tuple to its 1-based line."""
    root = _compose(_read_text(path), path)
    lines: dict[tuple, int] = {}
    if root is None:
        return {}, lines
    count = 0
    on_path: set[int] = set()   # nodes being expanded: an alias to one of them is a cycle

    def walk(node, keypath: tuple):
        nonlocal count
        where = f"{path}:{node.start_mark.line + 1}"
        count += 1
        if count > MAX_NODES:
            raise CaseError(f"{where}: more than {MAX_NODES} values once aliases (*name) are expanded; "
                            "a case file needs far fewer: remove the nested aliases")
        if len(keypath) > MAX_DEPTH:
            raise CaseError(f"{where}: nested more than {MAX_DEPTH} levels deep once aliases are "
                            "expanded: remove the nested aliases")
        lines.setdefault(keypath, node.start_mark.line + 1)
        if isinstance(node, yaml.ScalarNode):
            named = f"{where}: {dotted(keypath)}" if keypath else where
            return _core_scalar(node.value, named) if node.style is None else node.value
        if id(node) in on_path:
            raise CaseError(f"{where}: an alias refers to a value that contains it (a cycle); "
                            "remove the alias")
        on_path.add(id(node))
        try:
            if isinstance(node, yaml.MappingNode):
                out = {}
                for key_node, value_node in node.value:
                    key_where = f"{path}:{key_node.start_mark.line + 1}"
                    if not isinstance(key_node, yaml.ScalarNode):
                        raise CaseError(f"{key_where}: a key must be a name, not a list or a section")
                    if key_node.style is None and key_node.value == "<<":
                        raise CaseError(f"{key_where}: merge keys ('<<') are not supported; "
                                        + _MERGE_HINT)
                    named = f"{key_where}: {dotted(keypath)}" if keypath else key_where
                    key = _core_scalar(key_node.value, named) if key_node.style is None else key_node.value
                    key = str(key) if not isinstance(key, str) else key
                    if key in out:
                        raise CaseError(f"{key_where}: key '{key}' appears twice; keep one")
                    lines[keypath + (key,)] = key_node.start_mark.line + 1
                    out[key] = walk(value_node, keypath + (key,))
                return out
            items = []
            for index, item in enumerate(node.value):
                lines[keypath + (index,)] = item.start_mark.line + 1
                items.append(walk(item, keypath + (index,)))
            return items
        finally:
            on_path.discard(id(node))

    return walk(root, ()), lines
