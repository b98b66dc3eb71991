"""The one exception type of the postprocessor: its message names the file and what to do."""


class PostprocessError(Exception):
    """An input is missing or malformed; str(error) is the whole message for the user."""
