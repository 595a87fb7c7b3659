"""Output folders: checked before any work, and never a folder whose content vo-doppler did not
write.

A command's ``-o`` folder must be new, empty or written by an earlier run of the same command
(:func:`written_by`), must not be or contain one of the command's inputs nor lie inside an input
folder (a sequence folder, an image folder), and, when the command
replaces the whole folder (``run``; ``batch`` for each recording's folder), must not be the
current directory or hold it. ``vo-doppler run`` and each recording of ``vo-doppler batch`` fill
a temporary folder beside the output and swap it in only when complete (:func:`staged_output`;
:func:`begin_staging` and :func:`swap_in` for a caller that decides itself), so a failed run
leaves the previous results untouched and a rerun leaves no stale files. Folders are created
with the mode the umask gives, as by ``mkdir``.

A temporary folder names its owner (:data:`STAGING_OWNER`: host, process ID, and on Linux the
boot and the process's start), so that one a killed run left is recognised and deleted when the
output is written again (:func:`remove_cut_off_staging`), while that of a run still writing the
same output, or of one whose owner cannot be checked (another host, no owner file), is left.

How a folder is recognised as written by a command: the marker file :data:`MARKER` that every
command writes into the folders it makes, naming the command and, for a folder that is
replaced as a whole, every entry it wrote (an entry added later by someone else would be
deleted with the folder, so it makes replacing refused); or, for folders written before the
marker existed, the command's own files (:data:`_OWN_FILES`).
"""

from __future__ import annotations

import glob
import json
import os
import re
import secrets
import shutil
import socket
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from fnmatch import fnmatch
from pathlib import Path

from vo_doppler.errors import InputError, OutputError, storage_refused
from vo_doppler.io.yaml_file import load_yaml

MARKER = ".vo-doppler-output.json"
MARKER_FORMAT = "vo-doppler-output/1"
MARKER_MAX_BYTES = 1 << 20
STAGING_OWNER = ".vo-doppler-staging.json"
"""The file in a temporary folder naming the process writing it (removed before the swap)."""
RUN = "run"
"""The kind of folder ``run`` writes and ``batch`` writes per recording (one replaces the other)."""

_RUN_SUMMARY_KEYS = {"gnss_epochs", "tight_heading_availability", "final_wheel_scale"}
"""Keys every ``summary.json`` of ``run`` has held (the recognition of unmarked older outputs)."""
_RUN_FILES = ("*.tum", "*.png", "*.csv", "*.json", "*.html", "*.geojson", "*.log")
"""Name patterns of every file ``run`` and a ``batch`` recording have written."""
_WRITERS = {RUN: "'vo-doppler run' or 'vo-doppler batch'"}
"""Who writes a kind of folder, for messages (default: ``'vo-doppler COMMAND'``)."""
_BATCH_PREPARED = "prepared"
"""The sub-folder of a ``batch --comma2k19`` recording that holds its imported sequence."""


def _read_json(path: Path) -> object:
    """The JSON value in ``path``, or None when there is none to read (missing, too large, not
    JSON)."""
    try:
        if path.stat().st_size > MARKER_MAX_BYTES:
            return None
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def _json_with_keys(path: Path, keys: set[str]) -> bool:
    """Whether ``path`` is a JSON object holding ``keys``."""
    data = _read_json(path)
    return isinstance(data, dict) and keys <= data.keys()


def _manifest_with(folder: Path, test: Callable[[dict], bool]) -> bool:
    """Whether ``folder``'s ``sequence.yaml`` parses to a mapping that passes ``test``."""
    try:
        manifest = load_yaml(folder / "sequence.yaml", "the sequence manifest")
    except (InputError, OSError):
        return False
    return isinstance(manifest, dict) and test(manifest)


_LOG_LINE = re.compile(r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d,\d{3} [A-Z]+ vo_doppler[.\w]*: ")
"""The start of a line of a ``batch`` recording's ``run.log`` (``batch.process_recording``)."""


def _batch_log(path: Path) -> bool:
    """Whether ``path`` begins as a ``batch`` recording's log does."""
    try:
        with path.open(errors="replace") as stream:
            first = stream.readline(1000)
    except OSError:
        return False
    return bool(_LOG_LINE.match(first))


def _unmarked_run(folder: Path) -> bool:
    """A ``run`` output or ``batch`` recording folder from before the marker: its summary, batch
    marker or (a failed recording) log, and nothing else than files named like its outputs and
    a batch's ``prepared`` sequence (a folder an import wrote)."""
    entries = list(folder.iterdir())
    for entry in entries:
        if entry.name == _BATCH_PREPARED and entry.is_dir():
            if not written_by(entry, "import")[0]:
                return False
            continue
        if not entry.is_file() or not any(fnmatch(entry.name, p) for p in _RUN_FILES):
            return False
    names = {entry.name for entry in entries}
    return (
        _json_with_keys(folder / "summary.json", _RUN_SUMMARY_KEYS)
        or _json_with_keys(folder / "batch_done.json", {"fingerprint", "outputs"})
        or (
            "run.log" in names
            and names <= {"run.log", _BATCH_PREPARED}
            and _batch_log(folder / "run.log")
        )
    )


def _only_recordings(folder: Path) -> bool:
    """A batch's folder cut off before its aggregate: recording folders and nothing else."""
    return all(e.is_dir() and written_by(e, RUN)[0] for e in folder.iterdir())


_OWN_FILES: dict[str, Callable[[Path], bool]] = {
    RUN: _unmarked_run,
    "batch": lambda f: (f / "batch_summary.csv").is_file() or _only_recordings(f),
    "vo": lambda f: _json_with_keys(f / "vo_stats.json", {"metric_scale"}),
    "deadreckon": lambda f: (f / "deadreckon_summary.json").is_file(),
    "simulate": lambda f: _manifest_with(f, lambda m: {"scenario", "command"} <= m.keys()),
    "import": lambda f: _manifest_with(
        f, lambda m: "vo-doppler import comma2k19" in str(m.get("source", ""))
    ),
}
"""Per command, how a folder it wrote without a marker is recognised: by its own files."""


def _marker(folder: Path) -> dict | None:
    data = _read_json(folder / MARKER)
    if not isinstance(data, dict) or data.get("format") != MARKER_FORMAT:
        return None
    return data


def written_by(folder: str | Path, command: str) -> tuple[bool, list[str]]:
    """Whether ``folder`` (an existing folder) was written by ``command``, and the entries in it
    that the command's marker does not list (which make it foreign; empty when it has no list)."""
    folder = Path(folder)
    marker = _marker(folder)
    if marker is None:
        return _OWN_FILES[command](folder), []
    if marker.get("command") != command:
        return False, []
    listed = marker.get("entries")
    if not isinstance(listed, list):
        return True, []
    foreign = sorted(p.name for p in folder.iterdir() if p.name != MARKER and p.name not in listed)
    return True, foreign


def mark_output(folder: str | Path, command: str, complete: bool = True) -> None:
    """Write the marker that :func:`written_by` recognises into ``folder``; ``complete``: the
    folder holds everything the command writes, so its entries are listed."""
    folder = Path(folder)
    marker: dict = {"format": MARKER_FORMAT, "command": command}
    if complete:
        marker["entries"] = sorted(p.name for p in folder.iterdir() if p.name != MARKER)
    (folder / MARKER).write_text(json.dumps(marker, indent=1) + "\n")


def open_output_folder(path: str | Path, command: str) -> Path:
    """Create ``path`` (and its parents) for ``command`` to write into in place, marked as its
    own; the entries are not listed, as a command writing in place never deletes any."""
    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    mark_output(path, command, complete=False)
    return path


def _holds(folder: Path, other: Path) -> bool:
    return other == folder or other.is_relative_to(folder)


def check_output_folder(
    path: str | Path,
    command: str,
    inputs: Iterable[str | Path | None] = (),
    replace: bool = False,
) -> Path:
    """``path`` when ``command`` may write it (module docstring), an :class:`OutputError` saying
    why not otherwise. ``inputs``: the files and folders the command reads (None: an input not
    given); ``replace``: the command replaces the whole folder (its content is deleted), so it
    must not hold the current directory either. Nothing is created or changed."""
    path = Path(os.path.normpath(path))
    if path.is_symlink() and not path.exists():
        raise OutputError(
            f"{path}: a symbolic link to nothing ({os.readlink(path)}); give a folder"
        )
    if path.exists() and not path.is_dir():
        raise OutputError(f"{path}: the output exists and is not a folder")
    if replace and path.is_symlink():
        raise OutputError(
            f"{path}: a symbolic link, and the output folder is replaced as a whole; give the "
            f"folder itself ({path.resolve()})"
        )
    resolved = path.resolve()
    given = [item for item in inputs if item]
    for item in given:
        source = Path(item).resolve()
        if _holds(resolved, source):
            relation = "is" if source == resolved else "contains"
            raise OutputError(
                f"{path}: the output folder {relation} the input {item}; choose another folder"
            )
    for item in given:
        source = Path(item).resolve()
        if source.is_dir() and resolved.is_relative_to(source):
            raise OutputError(
                f"{path}: the output folder is inside the input folder {item}, which would then "
                "hold results beside its data (and, for a sequence, a later run read them as "
                "part of it); choose a folder outside it"
            )
    if replace and _holds(resolved, Path.cwd().resolve()):
        raise OutputError(
            f"{path}: the output folder is the current directory or contains it, and its "
            "content would be replaced; choose another folder"
        )
    ancestor = path.absolute()
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise OutputError(f"{path}: {ancestor} is not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK) or (
        path.exists() and not os.access(path.absolute().parent, os.W_OK | os.X_OK)
    ):
        raise OutputError(f"{path}: no permission to write there")
    try:
        if not path.is_dir() or not any(path.iterdir()):
            return path
        ours, foreign = written_by(path, command)
    except OSError as exc:
        raise OutputError(f"{path}: cannot read the output folder: {exc.strerror}") from exc
    writer = _WRITERS.get(command, f"'vo-doppler {command}'")
    if not ours:
        raise OutputError(
            f"{path}: the output folder is not empty and was not written by {writer}; "
            "choose a new or empty folder"
        )
    if replace and foreign:
        raise OutputError(
            f"{path}: the output folder holds what {writer} did not write "
            f"({', '.join(foreign)}), which replacing it would delete; move that away or "
            "choose another folder"
        )
    return path


def new_folder(parent: Path, prefix: str) -> Path:
    """A new folder ``parent/prefix<random>``, created as a plain ``mkdir`` would create it:
    with the mode the umask gives (``tempfile.mkdtemp`` makes it 0700, and a staged output
    swapped in kept that mode, unreadable to the other users whatever their umask)."""
    while True:
        folder = parent / f"{prefix}{secrets.token_hex(4)}"
        try:
            folder.mkdir()
        except FileExistsError:
            continue
        return folder


def begin_staging(path: str | Path, command: str, inputs: Iterable[str | Path | None] = ()) -> Path:
    """Check ``path`` as an output ``command`` replaces as a whole, delete the temporary folders
    that killed runs into it left (:func:`remove_cut_off_staging`) and create the one beside it
    to write into instead (hidden, ``.NAME.partial-*``, holding :data:`STAGING_OWNER`); the
    caller either swaps it in (:func:`swap_in`) or deletes it."""
    path = check_output_folder(path, command, inputs, replace=True).absolute()
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_cut_off_staging(path)
    staging = new_folder(path.parent, _staging_prefix(path))
    (staging / STAGING_OWNER).write_text(json.dumps(_this_process()) + "\n")
    return staging


def _staging_prefix(path: Path) -> str:
    return f".{path.name}.partial-"


def _read_text(path: str) -> str | None:
    try:
        with open(path) as stream:
            return stream.read()
    except OSError:
        return None


def _boot_id() -> str | None:
    """This boot of the machine (Linux), None where unknown."""
    text = _read_text("/proc/sys/kernel/random/boot_id")
    return None if text is None else text.strip()


def _process_start(pid: int) -> tuple[str, str] | None:
    """The state and start time (clock ticks after boot) of process ``pid`` (Linux), None where
    unknown or when there is no such process."""
    text = _read_text(f"/proc/{pid}/stat")
    if text is None:
        return None
    fields = text.rpartition(")")[2].split()
    return (fields[0], fields[19]) if len(fields) > 19 else None


def _this_process() -> dict:
    """What :data:`STAGING_OWNER` records: this process on this host, in this boot."""
    start = _process_start(os.getpid())
    return {
        "host": socket.gethostname(),
        "pid": os.getpid(),
        "boot_id": _boot_id(),
        "start": None if start is None else start[1],
    }


def _owner_gone(staging: Path) -> bool:
    """Whether the process that created ``staging`` has certainly ended: it ran on this host and
    either in an earlier boot, or its process ID names no process, a zombie, or a process
    started at another time (the ID reused). False whenever that cannot be known (no or an
    unreadable owner file, another host, no process table to ask)."""
    owner = _read_json(staging / STAGING_OWNER)
    if not isinstance(owner, dict) or owner.get("host") != socket.gethostname():
        return False
    pid = owner.get("pid")
    if not isinstance(pid, int) or isinstance(pid, bool) or pid <= 0 or os.name != "posix":
        return False
    boot = _boot_id()
    if owner.get("boot_id") is not None and boot is not None and owner["boot_id"] != boot:
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # another user's process (PermissionError): alive
        return False
    now = _process_start(pid)
    if now is None:
        return False
    state, start = now
    return state == "Z" or (owner.get("start") is not None and owner["start"] != start)


def remove_cut_off_staging(path: str | Path, alone: bool = False) -> None:
    """Delete the temporary folders beside ``path`` whose run was cut off (killed, power loss):
    no run reads them again. Without ``alone`` only those whose owner has certainly ended
    (:func:`_owner_gone`), so that a run still writing into ``path`` keeps its own; ``alone``:
    the caller alone writes ``path`` (a batch's recording), so every one is cut off."""
    path = Path(os.path.normpath(path)).absolute()
    for leftover in path.parent.glob(glob.escape(_staging_prefix(path)) + "*"):
        if leftover.is_dir() and not leftover.is_symlink() and (alone or _owner_gone(leftover)):
            shutil.rmtree(leftover, ignore_errors=True)


def swap_in(
    staging: Path, path: str | Path, command: str, inputs: Iterable[str | Path | None] = ()
) -> None:
    """Mark ``staging`` as ``command``'s and make it ``path``: ``path`` is checked again (it may
    have changed since :func:`begin_staging`), then the previous folder is removed. When the
    check fails, ``staging`` is removed, ``path`` left as it is and the error raised."""
    path = Path(os.path.normpath(path)).absolute()
    try:
        (staging / STAGING_OWNER).unlink(missing_ok=True)
        mark_output(staging, command)
        check_output_folder(path, command, inputs, replace=True)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    previous = None
    if path.exists():
        previous = new_folder(path.parent, f".{path.name}.old-")
        previous.rmdir()
        path.rename(previous)
    staging.rename(path)
    if previous is not None:
        shutil.rmtree(previous, ignore_errors=True)


@contextmanager
def staged_output(
    path: str | Path, command: str, inputs: Iterable[str | Path | None] = ()
) -> Iterator[Path]:
    """A temporary folder beside ``path`` to write into; on normal exit it is marked as
    ``command``'s and replaces ``path`` (:func:`swap_in`), on an exception it is removed and
    ``path`` is unchanged (the system refusing to store the files, a full disk, becomes an
    :class:`OutputError` naming ``path``)."""
    inputs = list(inputs)
    staging = begin_staging(path, command, inputs)
    try:
        yield staging
    except BaseException as exc:
        shutil.rmtree(staging, ignore_errors=True)
        if storage_refused(exc):  # a full disk: named as the output's, not the temporary's
            raise OutputError(f"{path}: cannot write the results: {exc.strerror}") from exc
        raise
    swap_in(staging, path, command, inputs)


def write_files(writers: Sequence[tuple[Path, Callable[[Path], None]]]) -> None:
    """Write files that are not in a staged folder: each ``(path, write)`` writes to a hidden
    file beside ``path`` (the same folder, so that :func:`os.replace` is a rename, and the same
    suffix, which chooses the format), and all are moved in place only once every one is
    written and flushed to disk. A failure (a full disk) leaves none of them, and the files of
    an earlier run as they were; after a crash or power loss each file is either the earlier
    one or the whole new one. Missing parent folders are created."""
    partial = [(path, path.with_name(f".{path.stem}.partial{path.suffix}")) for path, _ in writers]
    try:
        for (path, temporary), (_, write) in zip(partial, writers, strict=True):
            path.parent.mkdir(parents=True, exist_ok=True)
            write(temporary)
            with temporary.open("rb+") as stream:
                os.fsync(stream.fileno())
        for path, temporary in partial:
            os.replace(temporary, path)
    finally:
        for _, temporary in partial:
            temporary.unlink(missing_ok=True)


def untouched(path: str | Path) -> str:
    """What a failed run left at ``path``: the sentence for its message."""
    state = "left as it was" if Path(path).exists() else "not created"
    return f"nothing written: {path} {state}"
