"""Conditions that overlap once the node sets exist: two prescribed motions of one component on
nodes that two different sets share, where the solver would silently apply the later one (issue 17,
item 10: a body-wide condition overriding a clamp moved a clamped edge 1 mm).

Conditions on the same set are compared by name in pipeline/validate.py, before any mesh exists;
this check needs the discretized sets (preprocess), and runs before any file is written.
"""
from __future__ import annotations

import numpy as np

from .yaml_lines import CaseError


def _line(case: dict, *keypath) -> int:
    lines = case.get("_lines", {})
    while keypath and keypath not in lines:
        keypath = keypath[:-1]
    return lines.get(keypath, 1)


def check_condition_overlaps(case: dict, sets: dict) -> list[str]:
    """Raise CaseError for two different prescribed motions of one component on shared nodes;
    return warnings for an initial velocity that a prescribed motion overrides on some nodes.

    sets: node-set name → boolean mask over the nodes (NodeCloud.sets).
    """
    path = case.get("_path", "<case>")
    prescribed = []  # (index, kind, component, set, (times, values))
    for i, bc in enumerate(case["boundary_conditions"]):
        for kind in ("displacement", "velocity"):
            for comp, table in sorted((bc[kind] or {}).items()):
                prescribed.append((i, kind, comp, bc["set"], table))
    errors, warnings = [], []
    for a in range(len(prescribed)):
        for b in range(a + 1, len(prescribed)):
            i, kind_i, comp_i, set_i, table_i = prescribed[a]
            j, kind_j, comp_j, set_j, table_j = prescribed[b]
            if comp_i != comp_j or set_i == set_j or set_i not in sets or set_j not in sets:
                continue
            shared = int(np.count_nonzero(np.asarray(sets[set_i]) & np.asarray(sets[set_j])))
            if shared == 0 or (kind_i == kind_j and list(map(list, table_i)) == list(map(list, table_j))):
                continue  # a corner two edges share, both held the same way, is no conflict
            errors.append(
                f"{path}:{_line(case, 'boundary_conditions', j, kind_j, comp_j)}: boundary_conditions[{j}]."
                f"{kind_j}.{comp_j}: set '{set_j}' shares {shared} node(s) with set '{set_i}', whose component "
                f"{comp_i} is given another {kind_i} by boundary_conditions[{i}] (line "
                f"{_line(case, 'boundary_conditions', i, kind_i, comp_i)}); only the later would act on them: "
                "make the sets disjoint (a smaller set, a layer) or give both the same motion")
    for k, ic in enumerate(case["initial_conditions"]):
        for comp in sorted(ic["velocity"] or {}):
            for i, kind, comp_i, set_i, _ in prescribed:
                if comp_i != comp or ic["set"] == set_i or ic["set"] not in sets or set_i not in sets:
                    continue
                # A body given a velocity while its edge is held is the usual case (cases/drum); an
                # initial velocity that every node of its set ignores is the mistake.
                members = np.asarray(sets[ic["set"]])
                shared = int(np.count_nonzero(members & np.asarray(sets[set_i])))
                if shared and shared == int(np.count_nonzero(members)):
                    warnings.append(
                        f"{path}:{_line(case, 'initial_conditions', k, 'velocity', comp)}: initial_conditions[{k}]."
                        f"velocity.{comp}: all {shared} node(s) of set '{ic['set']}' are in set '{set_i}', whose "
                        f"{comp} is prescribed ({kind}, boundary_conditions[{i}]): the initial velocity is "
                        "ignored; remove it or prescribe the motion instead")
    if errors:
        raise CaseError("\n".join(errors))
    return warnings
