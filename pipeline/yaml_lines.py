"""Load a YAML file into plain Python objects while remembering the line of every key.

PyYAML's composer keeps a source mark on every node; we walk the node tree
ourselves so that an error about `time.safety_factor` can say "plate.yaml:14".
"""
from __future__ import annotations

import yaml


class CaseError(Exception):
    """A problem in a case file, with the file, the line and what to do in the message."""


def _scalar(node: yaml.ScalarNode, path: str):
    # Resolve the scalar with PyYAML's own implicit tag rules (1e-3 is a float
    # only with a dot in YAML 1.1, so we also accept plain '1e-3' as a float).
    loader = yaml.SafeLoader("")
    value = loader.construct_object(node, deep=True)
    if isinstance(value, str) and node.style is None:
        try:
            return float(value)
        except ValueError:
            return value
    return value


def load_with_lines(path: str):
    """Return (data, lines) where lines maps a key path tuple to its 1-based line."""
    try:
        with open(path, encoding="utf-8") as stream:
            text = stream.read()
    except OSError as err:
        raise CaseError(f"{path}: cannot read the case file: {err.strerror}") from None
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else path
        problem = getattr(err, "problem", None) or str(err)
        raise CaseError(f"{where}: not valid YAML: {problem}") from None
    lines: dict[tuple, int] = {}
    if root is None:
        return {}, lines

    def walk(node, keypath: tuple):
        lines.setdefault(keypath, node.start_mark.line + 1)
        if isinstance(node, yaml.MappingNode):
            out = {}
            for key_node, value_node in node.value:
                key = _scalar(key_node, ".".join(map(str, keypath)))
                key = str(key) if not isinstance(key, str) else key
                if key in out:
                    raise CaseError(
                        f"{path}:{key_node.start_mark.line + 1}: key '{key}' appears twice; keep one")
                lines[keypath + (key,)] = key_node.start_mark.line + 1
                out[key] = walk(value_node, keypath + (key,))
            return out
        if isinstance(node, yaml.SequenceNode):
            items = []
            for index, item in enumerate(node.value):
                lines[keypath + (index,)] = item.start_mark.line + 1
                items.append(walk(item, keypath + (index,)))
            return items
        return _scalar(node, ".".join(map(str, keypath)))

    return walk(root, ()), lines
