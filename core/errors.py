"""The one exception type for bad input. CLIs turn it into one stderr line, exit 2."""


class InputError(ValueError):
    """Bad user input: a scene file, an argument, a camera.

    The message is one line that says which file (or option), which line, which
    value and what was expected.
    """
