"""The image files of a recording, in order, held compactly: one folder and the file names.

A recording of 30 minutes at 15 frames per second has 27,000 images. As ``pathlib.Path``
objects (each with its own list of parts, name and cached string) they took about 9 MiB, held
through every stage of the run; as one folder and a tuple of names, about 2 MiB (issue 30;
docs/benchmarks.md, "Memory"). Each path is made when it is asked for.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from collections.abc import Sequence as AbstractSequence
from pathlib import Path
from typing import overload


class ImageFiles(AbstractSequence[Path]):
    """An immutable sequence of image paths: ``files[k]`` is ``folder / names[k]``.

    Built from any paths by :meth:`of` (all in one folder: that folder and the base names;
    otherwise an empty folder and each path whole), or from a folder and names by
    :meth:`in_folder`. Compares equal to another :class:`ImageFiles`, list or tuple of the same
    paths in the same order."""

    __slots__ = ("folder", "names")

    def __init__(self, folder: Path, names: tuple[str, ...]) -> None:
        self.folder = folder
        self.names = names

    @classmethod
    def in_folder(cls, folder: str | Path, names: Iterable[str]) -> ImageFiles:
        """The files ``names`` (base names, in this order) of ``folder``."""
        return cls(Path(folder), tuple(names))

    @classmethod
    def of(cls, paths: Iterable[str | Path]) -> ImageFiles:
        """``paths`` in their order (an :class:`ImageFiles` is returned as it is)."""
        if isinstance(paths, ImageFiles):
            return paths
        paths = [Path(p) for p in paths]
        folders = {p.parent for p in paths}
        if len(folders) == 1 and all(p.name for p in paths):
            return cls(folders.pop(), tuple(p.name for p in paths))
        return cls(Path(), tuple(str(p) for p in paths))

    def __len__(self) -> int:
        return len(self.names)

    @overload
    def __getitem__(self, index: int) -> Path: ...

    @overload
    def __getitem__(self, index: slice) -> ImageFiles: ...

    def __getitem__(self, index: int | slice) -> Path | ImageFiles:
        if isinstance(index, slice):
            return ImageFiles(self.folder, self.names[index])
        return self.folder / self.names[index]

    def __iter__(self) -> Iterator[Path]:
        folder = self.folder
        for name in self.names:
            yield folder / name

    def select(self, keep: Iterable[bool]) -> ImageFiles:
        """The files whose flag in ``keep`` (one per file) is true."""
        kept = (name for name, flag in zip(self.names, keep, strict=True) if flag)
        return ImageFiles(self.folder, tuple(kept))

    def __eq__(self, other: object) -> bool:
        if isinstance(other, ImageFiles):
            return list(self) == list(other)
        if isinstance(other, list | tuple):
            return list(self) == [Path(p) for p in other]
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"ImageFiles({str(self.folder)!r}, {len(self.names)} files)"

    def __reduce__(self) -> tuple[type[ImageFiles], tuple[Path, tuple[str, ...]]]:
        return ImageFiles, (self.folder, self.names)
