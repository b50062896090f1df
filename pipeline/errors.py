"""Exceptions shared by every stage."""


class UserInputError(ValueError):
    """Bad user input: the message names the file, the row or key, and the fix.

    The command line prints it as one line (no traceback) and exits with status 2.
    """
