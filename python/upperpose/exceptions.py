"""The exceptions upperpose raises, one tree under `UpperposeError`.

    UpperposeError
    ├── InputError   (also a ValueError) an argument's value is not allowed; the message names it
    ├── SearchError  a search could not run
    └── VideoError   a video or image cannot be read or written

Wrong argument types raise `TypeError`. The command line prints any of these as one line.
"""

from upperpose._upperpose import InputError, SearchError, UpperposeError


class VideoError(UpperposeError):
    """A video or image cannot be read or written."""


def one_line(err: BaseException) -> str:
    """The error's message on one line (OpenCV's span several)."""
    text = " ".join(str(err).split())
    return text or type(err).__name__


__all__ = ["InputError", "SearchError", "UpperposeError", "VideoError", "one_line"]
