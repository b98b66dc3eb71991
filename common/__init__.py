"""The ground floor of the Python side: what preprocess, postprocess, pipeline, peridyn, validation
and bench all need and that imports nothing of ours: atomic writes (atomic.py), an output folder's
lock (output_lock.py), opening only regular files (regular_file.py), the machine's memory
(memory.py), and where pdsolve and the Python interpreter are (paths.py)."""
