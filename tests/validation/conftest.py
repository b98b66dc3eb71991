"""The fast versions of the case checks (validation/): each test module runs a coarser, shorter
variant of its case through every stage and asserts the same numbers `make validate` reports."""
