"""Entry point of `/usr/bin/python3 -m postprocess OUT_DIR …` (see cli.py)."""
import sys

from .cli import main

sys.exit(main())
