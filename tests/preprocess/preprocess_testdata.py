"""Paths and geometry parameters shared by the preprocess tests (a unique module name, unlike conftest)."""
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")

# plate_hole.geo parameters [m]
PLATE = dict(L=0.1, W=0.05, r=0.01, g=0.01, lc=0.002, lc_hole=0.0005)
# box_hole.geo parameters [m]
BOX = dict(L=0.04, W=0.02, H=0.01, r=0.004, lc=0.002, lc_hole=0.0007)
