"""The videos of a batch: its inputs (videos, folders, globs, list files) expanded, each with its place.

A video's place is where its outputs go under the batch's folder, without suffix: its path
relative to the folder it was found in (a folder input, a glob's fixed leading folders, a list
file's folder), or to the current folder for a video named directly; a video outside that
folder, and a URL, is placed by its name.
"""

from __future__ import annotations

import glob
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from urllib.parse import urlparse

from upperpose.exceptions import InputError
from upperpose.io.video import is_stream_url

VIDEO_SUFFIXES = (".mp4", ".avi", ".mov", ".mkv", ".m4v", ".webm", ".mpg", ".mpeg", ".wmv", ".mts")
# A file with one of these suffixes lists videos (paths or URLs), one a line; "#" starts a comment.
LIST_SUFFIXES = (".txt", ".list", ".lst")


@dataclass(frozen=True)
class Video:
    """One video of a batch: what the tracker opens and where its outputs go (no suffix)."""

    source: str
    place: PurePosixPath


def find_videos(inputs: Sequence[str]) -> list[Video]:
    """The videos the inputs name, in the order given (a folder's and a glob's sorted by path).

    Raises:
        InputError: an input that does not exist, a folder or glob without a video, an empty
            list of inputs, or two videos that would write the same outputs.
    """
    if not inputs:
        raise InputError("no input: give videos, folders, globs or a list file")
    found: list[Video] = []
    for text in inputs:
        found += _expand(text, Path.cwd(), listed=False)
    return _checked(found)


def _expand(text: str, base: Path, *, listed: bool) -> list[Video]:
    """One input; `base` is the folder relative paths are taken from (a list file's)."""
    if is_stream_url(text):
        return [Video(text, PurePosixPath(Path(urlparse(text).path).stem or "stream"))]
    path = Path(text) if Path(text).is_absolute() else base / text
    if path.is_dir():
        videos = sorted(p for p in path.rglob("*") if p.suffix.lower() in VIDEO_SUFFIXES and _visible(p, path))
        if not videos:
            raise InputError(f"no video in the folder {text} (looked for {', '.join(VIDEO_SUFFIXES)})")
        return [Video(str(p), _place(p, path)) for p in videos]
    if path.is_file():
        if path.suffix.lower() in LIST_SUFFIXES and not listed:
            return _read_list(path)
        return [Video(str(path), _place(path, base))]
    if glob.has_magic(text):
        matches = sorted(Path(p) for p in glob.glob(str(path), recursive=True))
        videos = [p for p in matches if p.is_file() and p.suffix.lower() in VIDEO_SUFFIXES]
        if not videos:
            raise InputError(f"no video matches {text}")
        return [Video(str(p), _place(p, _fixed_part(path))) for p in videos]
    where = " (listed relative to its list file's folder)" if listed else ""
    raise InputError(f"no such video, folder or list file: {text}{where}")


def _read_list(path: Path) -> list[Video]:
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except UnicodeDecodeError:
        raise InputError(f"{path} is not a text file listing videos") from None
    entries = [line.strip() for line in lines if line.strip() and not line.strip().startswith("#")]
    if not entries:
        raise InputError(f"the list {path} names no video")
    return [video for entry in entries for video in _expand(entry, path.parent, listed=True)]


def _visible(path: Path, root: Path) -> bool:
    """False for files under hidden folders or hidden themselves (temporary files, .git)."""
    return not any(part.startswith(".") for part in path.relative_to(root).parts)


def _fixed_part(pattern: Path) -> Path:
    """A glob's leading folders without wildcards: its videos are placed relative to them."""
    fixed = []
    for part in pattern.parts:
        if glob.has_magic(part):
            break
        fixed.append(part)
    return Path(*fixed) if fixed else Path(".")


def _place(path: Path, root: Path) -> PurePosixPath:
    try:
        relative = Path(os.path.relpath(path, root))
    except ValueError:  # another drive (Windows)
        relative = Path(path.name)
    if relative.parts and relative.parts[0] == "..":
        relative = Path(path.name)
    return PurePosixPath(relative.as_posix()).with_suffix("")


def _checked(videos: list[Video]) -> list[Video]:
    """Drops repeats of one video; refuses two videos that would share outputs."""
    by_place: dict[PurePosixPath, Video] = {}
    seen: set[str] = set()
    out = []
    for video in videos:
        key = _key(video.source)
        other = by_place.get(video.place)
        if key in seen:
            continue
        if other is not None:
            raise InputError(
                f"{other.source} and {video.source} would both write {video.place}.json: "
                "give their common folder instead, so that the folder layout tells them apart"
            )
        seen.add(key)
        by_place[video.place] = video
        out.append(video)
    return out


def _key(source: str) -> str:
    """One name per video, however it was reached."""
    return source if is_stream_url(source) else str(Path(source).resolve())


__all__ = ["LIST_SUFFIXES", "VIDEO_SUFFIXES", "Video", "find_videos"]
