"""Open a ROS bag with rosbags: ROS 1 ``.bag``, ROS 2 sqlite3 or MCAP (the bag folder with its
``metadata.yaml``, or one ``.db3`` / ``.mcap`` file). Lists the topics and yields the decoded
messages of a topic with their index and receive time; every failure is an
:class:`~vo_doppler.errors.InputError` naming the bag, and for a message its topic and index.

Types: the definitions the bag carries (always in ROS 1, in ROS 2 bags from Iron on and in MCAP)
come first; rosbags' stock store (ROS 1 Noetic or ROS 2 Humble) and the project's definitions
(:mod:`vo_doppler.io.rosbag_types`) fill in the rest.
"""

from __future__ import annotations

import contextlib
import lzma
import sqlite3
import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import apsw
from rosbags.interfaces import MessageDefinitionFormat
from rosbags.rosbag1 import Reader as Reader1
from rosbags.rosbag1 import ReaderError as ReaderError1
from rosbags.rosbag2 import Reader as Reader2
from rosbags.rosbag2 import ReaderError as ReaderError2
from rosbags.serde import SerdeError
from rosbags.typesys import (
    Stores,
    TypesysError,
    get_types_from_idl,
    get_types_from_msg,
    get_typestore,
)

from vo_doppler.errors import InputError
from vo_doppler.io.rosbag_types import typestore as project_store

KIND_NAMES = {"ros1": "ROS 1", "ros2": "ROS 2"}
READABLE = "a ROS 1 .bag file, a ROS 2 bag folder (metadata.yaml), a .db3 or an .mcap file"
_ERRORS = (
    ReaderError1,
    ReaderError2,
    SerdeError,
    TypesysError,
    OSError,
    EOFError,
    KeyError,
    IndexError,
    ValueError,
    TypeError,
    AttributeError,
    AssertionError,
    OverflowError,
    MemoryError,
    RecursionError,
    UnicodeError,
    struct.error,
    sqlite3.Error,
    apsw.Error,
    zlib.error,
    lzma.LZMAError,
)
"""What rosbags and the libraries under it raise on a damaged bag (a bug in them surfaces as
one of these too; the message then still names the bag)."""


@dataclass(frozen=True)
class Topic:
    name: str
    msgtype: str
    count: int


def bag_kind(path: Path) -> str:
    """``ros1`` or ``ros2`` by the path's form; an :class:`InputError` for anything else."""
    if path.is_dir():
        if (path / "metadata.yaml").is_file():
            return "ros2"
        raise InputError(
            f"a folder without metadata.yaml is not a ROS 2 bag: give {READABLE}", path
        )
    if not path.is_file():
        raise InputError("no such bag", path)
    if path.suffix == ".bag":
        return "ros1"
    if path.suffix in (".db3", ".mcap"):
        return "ros2"
    raise InputError(f"unknown bag form {path.suffix!r}: give {READABLE}", path)


class Bag:
    """An open bag (use as a context manager)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.kind = bag_kind(self.path)
        self._reader = None
        self._store = None

    def __enter__(self) -> Bag:
        try:
            reader = Reader1(self.path) if self.kind == "ros1" else Reader2(self.path)
            reader.open()
        except _ERRORS as exc:
            raise InputError(
                f"cannot open the {KIND_NAMES[self.kind]} bag: {_text(exc)}", self.path
            ) from exc
        self._reader = reader
        try:
            self._store = self._typestore()
        except _ERRORS as exc:
            self.close()
            raise InputError(f"unusable message definitions: {_text(exc)}", self.path) from exc
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def close(self) -> None:
        if self._reader is not None:
            reader, self._reader = self._reader, None
            with contextlib.suppress(*_ERRORS):
                reader.close()

    def _typestore(self):
        """The bag's own definitions, and for each type it uses that it does not define, the
        stock or project definition (with the types it nests): only what the bag needs, as
        building a whole store's message classes takes seconds."""
        own: dict = {}
        for connection in self._reader.connections:
            definition = connection.msgdef
            if definition.format == MessageDefinitionFormat.MSG and definition.data.strip():
                own.update(get_types_from_msg(definition.data, connection.msgtype))
            elif definition.format == MessageDefinitionFormat.IDL and definition.data.strip():
                own.update(_idl_types(definition.data))
        ros2 = self.kind == "ros2"
        fill = project_store(ros2)
        for connection in self._reader.connections:
            name = connection.msgtype
            if name not in own and name in fill.types:
                text = fill.generate_msgdef(name, ros_version=2 if ros2 else 1)[0]
                own.update(
                    {k: v for k, v in get_types_from_msg(text, name).items() if k not in own}
                )
        store = get_typestore(Stores.EMPTY)
        store.register(own)
        return store

    def start_s(self) -> float:
        """The receive time (s) of the bag's first message (0 for an empty bag)."""
        try:
            return self._reader.start_time * 1e-9 if self._reader.message_count else 0.0
        except _ERRORS:
            return 0.0

    def topics(self) -> list[Topic]:
        """Every topic with its message type and count, sorted by name."""
        counts: dict[str, list] = {}
        for connection in self._reader.connections:
            entry = counts.setdefault(connection.topic, [connection.msgtype, 0])
            entry[1] += connection.msgcount
        return [Topic(name, kind, int(count)) for name, (kind, count) in sorted(counts.items())]

    def msgtype(self, topic: str) -> str:
        for item in self.topics():
            if item.name == topic:
                return item.msgtype
        names = ", ".join(t.name for t in self.topics()) or "none"
        raise InputError(f"no topic {topic} in the bag (topics: {names})", self.path)

    def messages(self, topic: str) -> Iterator[tuple[int, int, object]]:
        """(index in the topic, receive time in ns, decoded message) in bag order."""
        msgtype = self.msgtype(topic)
        connections = [c for c in self._reader.connections if c.topic == topic]
        index = -1
        stream = self._reader.messages(connections=connections)
        while True:
            try:
                item = next(stream, None)
            except _ERRORS as exc:
                raise self.error(topic, index + 1, f"unreadable record: {_text(exc)}") from exc
            if item is None:
                return
            index += 1
            connection, receive_ns, raw = item
            try:
                if self.kind == "ros1":
                    message = self._store.deserialize_ros1(raw, connection.msgtype)
                else:
                    message = self._store.deserialize_cdr(raw, connection.msgtype)
            except _ERRORS as exc:
                raise self.error(topic, index, f"cannot decode {msgtype}: {_text(exc)}") from exc
            yield index, int(receive_ns), message

    def error(self, topic: str, index: int, message: str) -> InputError:
        """An :class:`InputError` naming the bag, topic and message index."""
        return InputError(f"topic {topic}, message {index}: {message}", self.path)


def _idl_types(data: str) -> dict:
    separator = "=" * 80 + "\n"
    if not data.startswith(separator + "IDL: "):
        return get_types_from_idl(data)
    types: dict = {}
    for part in data.split(separator)[1:]:
        types.update(get_types_from_idl(part.split("\n", 1)[1] if "\n" in part else ""))
    return types


def _text(exc: BaseException) -> str:
    text = str(exc).strip() or type(exc).__name__
    return text if len(text) < 300 else text[:300] + "…"
