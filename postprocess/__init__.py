"""Postprocessor of the solver's output (pipeline/formats.md §4): readers, figures and Gmsh views.

    /usr/bin/python3 -m postprocess OUT_DIR [--case-json PATH] [--only figures|gmsh]

The package imports no plotting library at import time; matplotlib is loaded (Agg backend,
never a display) by the modules that draw.
"""
from .errors import PostprocessError
from .history import HISTORY_COLUMNS, read_history
from .series import Frame, read_frame, read_series
from .selection import default_times, select_frames

__all__ = ["PostprocessError", "HISTORY_COLUMNS", "read_history", "Frame", "read_frame",
           "read_series", "default_times", "select_frames"]
