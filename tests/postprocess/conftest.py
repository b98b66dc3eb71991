"""Fixtures of the postprocess tests: a small synthetic solver output that follows formats.md §4."""

import pytest

import synthetic_output


@pytest.fixture
def run2d(tmp_path):
    """A 2D run: 9 × 7 lattice, 6 frames, a crack growing from frame 2 on, 41 history rows."""
    return synthetic_output.make_run(tmp_path / "out" / "plate", dimension=2)


@pytest.fixture
def run3d(tmp_path):
    """A 3D run: 5 × 4 × 3 lattice, 4 frames."""
    return synthetic_output.make_run(tmp_path / "out" / "block", dimension=3, shape=(5, 4, 3), frames=4)


@pytest.fixture
def gmsh_session():
    """gmsh's own API, initialised quietly without reading the user's config, finalised after the test."""
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        yield gmsh
    finally:
        gmsh.finalize()
