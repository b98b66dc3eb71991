"""Quantitative checks of the cases and the validation suite (`make validate`): each module reads
a finished run in out/<case>/ and returns Check rows (quantity, expected, measured, pass)."""
