"""Per-process FMU state: the extracted FMU and its instances, built once and reused.

A simulator object is pickled to every worker, possibly more than once; all copies of one FMU in
a process share one extracted folder and a small pool of instances (one per concurrently
running thread), so extraction and instantiation happen once per process, not per evaluation.
"""

from __future__ import annotations

import atexit
import collections
import ctypes
import io
import os
import shutil
import tempfile
import threading
import zipfile
from pathlib import Path

import simgap

# How often this process extracted an FMU, instantiated one, and reset an instance for reuse.
# Tests and benchmarks read them through process_counts() to prove the reuse.
_counts = collections.Counter()

_lock = threading.Lock()
_extracted: dict[str, Path] = {}
_idle: dict[tuple[str, str], list["FMURuntime"]] = {}
_owner_pid = os.getpid()

_LOG_LINES_KEPT = 20
_STATUS_LABELS = ("OK", "warning", "discard", "error", "fatal", "pending")


def process_counts() -> dict[str, int]:
    """Extractions, instantiations and resets done in this process so far."""
    return {key: _counts[key] for key in ("extractions", "instantiations", "resets")}


def count(event: str) -> None:
    """Count an instantiation or a reset done by a runtime of another FMI version (fmi3.py)."""
    _counts[event] += 1


class FMIStatusError(Exception):
    """An FMI function returned error or fatal; ``fatal`` means the instance is unusable."""

    def __init__(self, function: str, status: int, model_time: float | None, log: list[str]):
        self.function = function
        self.status = status
        self.fatal = status >= 4
        label = _STATUS_LABELS[status] if 0 <= status < len(_STATUS_LABELS) else f"status {status}"
        where = f" in the step from t={model_time:g} s" if function.endswith("DoStep") and model_time is not None else (f" at t={model_time:g} s" if model_time is not None else "")
        detail = f": {log[-1]}" if log else ""
        super().__init__(f"{function} returned {label}{where}{detail}")


class FMURuntime:
    """One extracted FMU and one FMI 2.0 instance of it, with raw entry points for the step loop."""

    def __init__(self, digest: str, fmu_bytes: bytes, fmi_type: str):
        from fmpy.fmi2 import FMU2Model, FMU2Slave
        from fmpy.model_description import read_model_description

        self.digest = digest
        self.fmi_type = fmi_type
        self.unzip_dir = extract(digest, fmu_bytes)
        self.description = read_model_description(str(self.unzip_dir), validate=False)
        # the FMU's own messages, so a failed run can say in its words what went wrong
        self._log = simgap.FMULog(keep=_LOG_LINES_KEPT)
        self.log = self._log.lines
        self._callbacks = self._log.callbacks

        if fmi_type == "CoSimulation":
            interface, cls = self.description.coSimulation, FMU2Slave
        else:
            interface, cls = self.description.modelExchange, FMU2Model
        self.fmu = cls(
            guid=self.description.guid,
            modelIdentifier=interface.modelIdentifier,
            unzipDirectory=str(self.unzip_dir),
            instanceName="simgap",
        )
        self.fmu.instantiate(callbacks=self._callbacks, loggingOn=False)
        _counts["instantiations"] += 1
        self.component = self.fmu.component
        self.used = False
        self.prepared_cases: collections.OrderedDict = collections.OrderedDict()

        # Fresh function objects (dll[name] does not share fmpy's) typed with plain addresses,
        # so the step loop passes precomputed integers instead of building ctypes pointers.
        dll = self.fmu.dll
        self.set_real = _function(dll, "fmi2SetReal", ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p)
        self.get_real = _function(dll, "fmi2GetReal", ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p)
        if fmi_type == "CoSimulation":
            self.do_step = _function(dll, "fmi2DoStep", ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int)
        self.chunk_steps = 1000  # adapted by the step loop to about steploop.CHUNK_SECONDS
        self._function_addresses = None

    def function_addresses(self) -> tuple:
        """fmi2SetReal, fmi2GetReal, fmi2DoStep for the compiled step loop."""
        if self._function_addresses is None:
            from .steploop import function_addresses

            self._function_addresses = function_addresses(self.fmu.dll)
        return self._function_addresses

    def check(self, function: str, status: int, model_time: float | None = None) -> None:
        if status > 1:
            raise FMIStatusError(function, status, model_time, list(self.log))

    def begin_run(self) -> None:
        """Bring the instance back to 'instantiated' (fmi2Reset after a previous run)."""
        self.log.clear()
        self._log.claim()
        if self.used:
            status = self._reset()
            self.check("fmi2Reset", status)
            _counts["resets"] += 1
        self.used = True

    def _reset(self) -> int:
        return self.fmu._functions["fmi2Reset"](self.component)

    def free(self) -> None:
        try:
            self.fmu.freeInstance()
        except Exception:
            pass
        self._log.close()


def _function(dll, name: str, *argtypes):
    function = dll[name]
    function.argtypes = argtypes
    function.restype = ctypes.c_int
    return function


def extract(digest: str, fmu_bytes: bytes) -> Path:
    """The folder this process extracted the FMU into (extracting it on the first call)."""
    with _lock:
        folder = _extracted.get(digest)
        if folder is not None and folder.is_dir():
            return folder
        _remove_orphaned_folders()
        folder = Path(tempfile.mkdtemp(prefix=f"{_FOLDER_PREFIX}{os.getpid()}-"))
        with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as archive:
            archive.extractall(folder)
        _extracted[digest] = folder
        _counts["extractions"] += 1
        return folder


# Extracted folders are named simgap-fmu-<pid>-<random> in the temporary directory. A process
# that exits normally removes its own (atexit); one that crashed inside the FMU, was killed for
# hanging, or was a forked worker leaving through os._exit cannot, so the next process to
# extract removes the folders whose process no longer exists. A crashing third-party FMU
# restarted a thousand times would otherwise leave a thousand copies of itself in /tmp.
_FOLDER_PREFIX = "simgap-fmu-"
_swept_pid: int | None = None


def _process_exists(pid: int) -> bool:
    try:
        os.kill(pid, 0)  # signal 0: only asks whether the process exists
    except ProcessLookupError:
        return False
    except OSError:  # PermissionError: another user's process
        return True
    return True


def _remove_orphaned_folders() -> None:
    """Delete this user's extracted folders whose process has gone (once per process)."""
    global _swept_pid
    if _swept_pid == os.getpid() or os.name != "posix":  # os.kill(pid, 0) terminates on Windows
        return
    _swept_pid = os.getpid()
    try:
        entries = list(Path(tempfile.gettempdir()).glob(f"{_FOLDER_PREFIX}*-*"))
    except OSError:
        return
    for folder in entries:
        pid_text = folder.name[len(_FOLDER_PREFIX):].split("-", 1)[0]
        if not pid_text.isdigit() or int(pid_text) == os.getpid():
            continue
        try:
            if folder.stat().st_uid != os.getuid() or not folder.is_dir():
                continue
        except OSError:
            continue
        if not _process_exists(int(pid_text)):
            shutil.rmtree(folder, ignore_errors=True)


_loaded_libraries: dict[str, ctypes.CDLL] = {}  # kept referenced: unloading would break the FMU


def prepare_process(libraries: tuple[str, ...], environment: dict[str, str]) -> None:
    """Set ``environment`` and load ``libraries`` (RTLD_GLOBAL, so the FMU's binary resolves its
    symbols against them) in this process, once; a library that cannot be loaded is a ModelError
    naming it and the option."""
    for key, value in environment.items():
        if os.environ.get(key) != value:
            os.environ[key] = value
    for library in libraries:
        if library in _loaded_libraries:
            continue
        try:
            _loaded_libraries[library] = ctypes.CDLL(library, mode=ctypes.RTLD_GLOBAL)
        except OSError as exc:
            raise simgap.ModelError(
                f"simulator.options.libraries: cannot load {library!r} ({exc}); "
                f"expected a path (relative to the workflow) or a name the system loader finds"
            ) from None


def acquire(digest: str, fmu_bytes: bytes, fmi_type: str, runtime_class: type | None = None) -> FMURuntime:
    """An idle runtime for this FMU, or a new one (extracting the FMU if this process has not).
    ``runtime_class`` builds it: ``FMURuntime`` (FMI 2.0) unless given (``fmi3.FMU3Runtime``)."""
    _forget_parent_state()
    with _lock:
        pool = _idle.get((digest, fmi_type))
        if pool:
            return pool.pop()
    return (runtime_class or FMURuntime)(digest, fmu_bytes, fmi_type)


def release(runtime: FMURuntime, *, broken: bool = False) -> None:
    """Return a runtime to the pool, or free it if its instance cannot be reused."""
    if broken:
        runtime.free()
        return
    with _lock:
        _idle.setdefault((runtime.digest, runtime.fmi_type), []).append(runtime)


def discard(digest: str) -> None:
    """Free the idle instances of one FMU and delete its extracted folder."""
    with _lock:
        runtimes = [r for key, pool in list(_idle.items()) if key[0] == digest for r in _idle.pop(key)]
        folder = _extracted.pop(digest, None)
    for runtime in runtimes:
        runtime.free()
    if folder is not None:
        shutil.rmtree(folder, ignore_errors=True)


def _forget_parent_state() -> None:
    # A forked child inherits the parent's pool; the parent deletes the folders at its exit, so
    # the child starts its own.
    global _owner_pid
    if os.getpid() != _owner_pid:
        with _lock:
            _idle.clear()
            _extracted.clear()
            _owner_pid = os.getpid()


@atexit.register
def _remove_extracted_folders() -> None:
    if os.getpid() != _owner_pid:
        return
    for folder in list(_extracted.values()):
        shutil.rmtree(folder, ignore_errors=True)
    _extracted.clear()
