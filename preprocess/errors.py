"""The one exception (and warning) type of the preprocessor; messages start with the file they concern."""
from __future__ import annotations


class PreprocessError(Exception):
    """A problem with an input of the preprocessor; the message starts with the file path and says what to do."""


class PreprocessWarning(UserWarning):
    """Something suspicious that does not stop the stage (degenerate elements, say)."""
