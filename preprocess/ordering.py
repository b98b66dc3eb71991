"""Space-filling-curve (Morton / Z-order) numbering of the node cloud, applied before the node file
is written, so that nodes close in space are close in memory.

Why: the solver's bond loop (solver/src/forces/pmb.cpp) reads the positions of a node's partners
through their indices; when partners are near in index they share cache lines, and a row's partners
stay in cache from one row to the next. A lattice written x-fastest already has this locality along
x, but a gmsh mesh numbers its nodes entity by entity (corners, then curves, then surfaces), which
scatters the partners of a node over the whole array. Sorting along a Z-order curve bounds the index
distance of spatial neighbours for every cloud, whatever produced it (docs/performance.md §5).

Sorting in the pre-processor instead of at load in the solver keeps one numbering for every file:
the node file, the frames and the node sets all use the same index, so a user can compare a frame
with nodes.vtu node by node. The order is stable (ties keep their input order), so the sort is
deterministic.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .cloud import NodeCloud

_BITS = 21  # per axis: 3 × 21 = 63 bits in a uint64 Morton key


def _spread_bits(v: np.ndarray) -> np.ndarray:
    """Insert two zero bits between the low 21 bits of each value (the classic magic-number
    bit interleave for 3D Morton codes)."""
    v = v.astype(np.uint64) & np.uint64(0x1FFFFF)
    v = (v | (v << np.uint64(32))) & np.uint64(0x1F00000000FFFF)
    v = (v | (v << np.uint64(16))) & np.uint64(0x1F0000FF0000FF)
    v = (v | (v << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    v = (v | (v << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    v = (v | (v << np.uint64(2))) & np.uint64(0x1249249249249249)
    return v


def morton_keys(points: np.ndarray, spacing: float) -> np.ndarray:
    """The Z-order key of each point on a grid of cell size `spacing` anchored at the cloud's lower
    corner. Clouds wider than 2²¹ cells along an axis use a coarser cell, so keys never overflow."""
    points = np.asarray(points, dtype=np.float64)
    if len(points) == 0:
        return np.zeros(0, dtype=np.uint64)
    lower = points.min(axis=0)
    extent = float(np.max(points.max(axis=0) - lower))
    cell = max(float(spacing), extent / (2 ** _BITS - 1), np.finfo(float).tiny)
    cells = np.floor((points - lower) / cell).astype(np.int64)
    cells = np.clip(cells, 0, 2 ** _BITS - 1)
    return (_spread_bits(cells[:, 0]) | (_spread_bits(cells[:, 1]) << np.uint64(1))
            | (_spread_bits(cells[:, 2]) << np.uint64(2)))


def morton_order(points: np.ndarray, spacing: float) -> np.ndarray:
    """The permutation that sorts the points along the Z-order curve (stable)."""
    return np.argsort(morton_keys(points, spacing), kind="stable")


def reorder(cloud: NodeCloud, order: np.ndarray) -> NodeCloud:
    """The same cloud with node k of the result = node order[k] of the input: every per-node array
    (points, volume, block, each node set) is permuted together."""
    return dataclasses.replace(
        cloud,
        points=np.ascontiguousarray(cloud.points[order]),
        volume=np.ascontiguousarray(cloud.volume[order]),
        block=np.ascontiguousarray(cloud.block[order]),
        sets={name: np.ascontiguousarray(mask[order]) for name, mask in cloud.sets.items()},
    )


def space_filling_order(cloud: NodeCloud) -> NodeCloud:
    """The cloud numbered along the Z-order curve with cells of the cloud's grid spacing."""
    return reorder(cloud, morton_order(cloud.points, cloud.grid_spacing))
