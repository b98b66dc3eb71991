"""The smallest valid case files and node cloud, shared by the pipeline tests that vary one key of them."""
import numpy as np

from preprocess.cloud import NodeCloud

MINIMAL = """\
dimension: 2
thickness: 0.001
discretization:
  dx: 0.001
materials:
  plate:
    density: 2000
    youngs_modulus: 1.0e9
time:
  end: 1.0e-3
"""

# A PMMA-like plate: realistic SI values that must pass without any warning. Tests name its lines
# (time.end is line 10), so keys are only ever appended to it.
PMMA_PLATE = """\
dimension: 2
thickness: 0.001
discretization:
  dx: 0.001
materials:
  plate:
    density: 1190
    youngs_modulus: 3.2e9
time:
  end: 1.0e-4
"""


def lattice_cloud(nx=12, ny=10, dx=0.001, thickness=0.001, extra=()):
    """An nx × ny square lattice of spacing dx in the z = 0 plane (plus the `extra` points), each
    node of volume dx² × thickness, one block, no node sets: the cloud of PMMA_PLATE."""
    pts = np.array([[i * dx, j * dx, 0.0] for j in range(ny) for i in range(nx)] + list(extra))
    n = len(pts)
    return NodeCloud(points=pts, volume=np.full(n, dx * dx * thickness), block=np.ones(n, np.int32),
                     sets={}, grid_spacing=dx, dimension=2)
