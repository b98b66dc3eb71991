"""NodeCloud: the discretized body that the node file stores (pipeline/formats.md §2)."""
from __future__ import annotations

import dataclasses
import re

import numpy as np

SET_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


@dataclasses.dataclass
class NodeCloud:
    points: np.ndarray            # (n, 3) float64, z = 0 in 2D [m]
    volume: np.ndarray            # (n,) float64 [m³]; 2D: area × thickness
    block: np.ndarray             # (n,) int32, 1-based block index
    sets: dict[str, np.ndarray]   # name -> (n,) bool
    grid_spacing: float           # [m]
    dimension: int                # 2 or 3

    def problems(self) -> list[str]:
        """What makes this cloud invalid for the node file (empty list when it is valid)."""
        n = len(self.points)
        out = []
        if self.dimension not in (2, 3):
            out.append(f"dimension is {self.dimension}, must be 2 or 3")
        if np.shape(self.points) != (n, 3) or n == 0:
            out.append(f"points have shape {np.shape(self.points)}, expected (n, 3) with n > 0")
        elif not np.all(np.isfinite(self.points)):
            out.append("some coordinates are not finite")
        elif self.dimension == 2 and np.any(self.points[:, 2] != 0):
            out.append("a 2D cloud must have z = 0")
        if np.shape(self.volume) != (n,):
            out.append(f"volume has shape {np.shape(self.volume)}, expected ({n},)")
        elif not np.all(np.isfinite(self.volume) & (self.volume > 0)):
            out.append(f"{int(np.sum(~(self.volume > 0)))} node(s) have a volume that is not > 0")
        if np.shape(self.block) != (n,):
            out.append(f"block has shape {np.shape(self.block)}, expected ({n},)")
        elif np.any(np.asarray(self.block) < 1):
            out.append(f"{int(np.sum(np.asarray(self.block) < 1))} node(s) have no block (block < 1)")
        if not (np.isfinite(self.grid_spacing) and self.grid_spacing > 0):
            out.append(f"grid_spacing is {self.grid_spacing}, must be > 0")
        for name, mask in self.sets.items():
            if not SET_NAME.match(name):
                out.append(f"node set name '{name}' does not match [A-Za-z_][A-Za-z0-9_]*")
            if np.shape(mask) != (n,):
                out.append(f"node set '{name}' has shape {np.shape(mask)}, expected ({n},)")
        return out
