"""The exceptions upperpose raises besides ValueError and TypeError for bad arguments."""

from upperpose._upperpose import UpperposeError


class VideoError(UpperposeError):
    """A video or image cannot be read or written."""


__all__ = ["UpperposeError", "VideoError"]
