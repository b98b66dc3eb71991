"""The fast versions of the case checks (validation/): each test module runs a coarser, shorter
variant of its case through every stage and asserts the same numbers `make validate` reports."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)
