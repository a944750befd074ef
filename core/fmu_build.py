"""Build an FMI 2.0 or 3.0 FMU from a folder of C sources and a hand-written ``modelDescription.xml``.

The FMI version comes from the XML: the headers of both (``fmi2Functions.h``, ``fmi3Functions.h``)
are fmpy's, and the binary goes where the version puts it (``binaries/linux64`` for 2.0,
``binaries/x86_64-linux`` for 3.0).

The result is cached under ``<cache_dir>/fmus/<modelIdentifier>-<hash>.fmu``: the hash covers the
sources, the XML and the compiler command, so an edit rebuilds and an unchanged folder does not.
"""

from __future__ import annotations

import hashlib
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

from .errors import ModelError

# Bump when the build recipe changes in a way the hash of the inputs would not show.
_RECIPE_VERSION = "1"
_COMPILE_FLAGS = ("-shared", "-fPIC", "-O2")
_SOURCE_SUFFIXES = (".c", ".h")
# where each FMI major version keeps the Linux binary
_BINARY_FOLDERS = {"2": "binaries/linux64", "3": "binaries/x86_64-linux"}


def build_fmu(source_dir: Path, cache_dir: Path) -> Path:
    """Compile ``source_dir`` into an FMU (Linux, gcc) and return the path of the cached ``.fmu``."""
    source_dir = Path(source_dir)
    if not sys.platform.startswith("linux"):
        raise ModelError(
            f"{source_dir}: building an FMU from C sources is supported on Linux only "
            f"(this is {sys.platform}); build the FMU elsewhere and give its path under 'fmu'"
        )
    xml_path = source_dir / "modelDescription.xml"
    if not source_dir.is_dir():
        raise ModelError(f"{source_dir}: FMU source folder not found")
    if not xml_path.is_file():
        raise ModelError(f"{source_dir}: no modelDescription.xml in the FMU source folder")
    c_files = sorted(source_dir.glob("*.c"))
    if not c_files:
        raise ModelError(f"{source_dir}: no *.c files in the FMU source folder")

    identifiers, fmi_version = _model_identifiers(xml_path)
    compiler = os.environ.get("CC", "gcc")
    compiler_path = shutil.which(compiler)
    if compiler_path is None:
        raise ModelError(
            f"{source_dir}: C compiler '{compiler}' not found; install gcc (e.g. apt-get install gcc) "
            "or set CC, or give a built FMU under 'fmu'"
        )
    include_dir = _fmi_headers()

    digest = _source_digest(source_dir, compiler_path, c_files, include_dir)
    target = Path(cache_dir) / "fmus" / f"{identifiers[0]}-{digest}.fmu"
    if target.is_file():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)

    with tempfile.TemporaryDirectory(prefix="simgap-build-") as tmp:
        tmp_dir = Path(tmp)
        libraries = {}
        for identifier in identifiers:
            library = tmp_dir / f"{identifier}.so"
            command = [
                compiler_path,
                *_COMPILE_FLAGS,
                f"-I{source_dir}",
                f"-I{include_dir}",
                "-o",
                str(library),
                *map(str, c_files),
                "-lm",
            ]
            _compile(command, source_dir)
            libraries[identifier] = library

        # Write next to the target so os.replace stays on one file system (atomic rename):
        # a second process building the same FMU at the same time just replaces it with an
        # identical file, and readers never see a half-written one.
        fd, partial = tempfile.mkstemp(prefix=f".{target.stem}-", suffix=".partial", dir=target.parent)
        os.close(fd)
        try:
            with zipfile.ZipFile(partial, "w", compression=zipfile.ZIP_DEFLATED) as fmu:
                fmu.write(xml_path, "modelDescription.xml")
                for identifier, library in libraries.items():
                    fmu.write(library, f"{_BINARY_FOLDERS[fmi_version]}/{identifier}.so")
                for source in sorted(source_dir.iterdir()):
                    if source.suffix in _SOURCE_SUFFIXES:
                        fmu.write(source, f"sources/{source.name}")
            _validate(Path(partial), source_dir)
            os.replace(partial, target)
        finally:
            if os.path.exists(partial):
                os.unlink(partial)
    return target


def _model_identifiers(xml_path: Path) -> tuple[list[str], str]:
    from fmpy.model_description import read_model_description

    try:
        description = read_model_description(str(xml_path), validate=False)
    except Exception as exc:  # fmpy raises plain exceptions for XML and schema problems
        raise ModelError(f"{xml_path}: not a valid FMI model description: {_first_line(exc)}") from None
    fmi_version = description.fmiVersion.split(".")[0]
    if fmi_version not in _BINARY_FOLDERS:
        raise ModelError(
            f"{xml_path}: fmiVersion is '{description.fmiVersion}', the C-source builder handles FMI 2.0 and 3.0"
        )
    identifiers = []
    for interface in (description.coSimulation, description.modelExchange):
        if interface is not None and interface.modelIdentifier not in identifiers:
            identifiers.append(interface.modelIdentifier)
    if not identifiers:
        raise ModelError(f"{xml_path}: declares neither <CoSimulation> nor <ModelExchange>")
    return identifiers, fmi_version


def _fmi_headers() -> Path:
    import fmpy

    include_dir = Path(fmpy.__file__).parent / "c-code"
    for header in ("fmi2Functions.h", "fmi3Functions.h"):
        if not (include_dir / header).is_file():
            raise ModelError(f"the FMI header {header} is missing from fmpy's installation ({include_dir})")
    return include_dir


def _source_digest(source_dir: Path, compiler: str, c_files: list[Path], include_dir: Path) -> str:
    """Hash of the recipe and of every file the compiler reads (sources may include shared files
    from elsewhere, as the example models include ../common/fmi2_glue.c)."""
    digest = hashlib.sha256()
    digest.update(f"recipe {_RECIPE_VERSION} {Path(compiler).name} {' '.join(_COMPILE_FLAGS)}\n".encode())
    files = [source_dir / "modelDescription.xml", *_dependencies(compiler, c_files, source_dir, include_dir)]
    for path in files:
        digest.update(f"{path.name}\n{path.stat().st_size}\n".encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def _dependencies(compiler: str, c_files: list[Path], source_dir: Path, include_dir: Path) -> list[Path]:
    """The sources and non-system headers the compiler reads (``-MM``), in a stable order."""
    command = [compiler, "-MM", f"-I{source_dir}", f"-I{include_dir}", *map(str, c_files)]
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=60)
    except OSError:
        result = None
    if result is None or result.returncode != 0:  # the compile itself will report why
        return sorted(p for p in source_dir.iterdir() if p.suffix in _SOURCE_SUFFIXES)
    words = result.stdout.replace("\\\n", " ").split()
    paths = {Path(w).resolve() for w in words if not w.endswith(":")}
    return sorted(paths, key=lambda p: (p.name, str(p)))


def _compile(command: list[str], source_dir: Path) -> None:
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    except OSError as exc:
        raise ModelError(f"{source_dir}: cannot run the C compiler {command[0]}: {exc}") from None
    if result.returncode != 0:
        lines = [line for line in result.stderr.splitlines() if line.strip()]
        errors = [line for line in lines if "error" in line.lower()] or lines
        excerpt = " | ".join(errors[:3]) or f"exit status {result.returncode}"
        raise ModelError(
            f"{source_dir}: compiling the FMU failed: {excerpt} (command: {shlex.join(command)})"
        )


def _validate(fmu_path: Path, source_dir: Path) -> None:
    from fmpy.validation import validate_fmu

    problems = validate_fmu(str(fmu_path))
    if problems:
        raise ModelError(
            f"{source_dir}: the built FMU does not pass fmpy's validation: " + "; ".join(problems[:3])
        )


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip() or type(exc).__name__
    return text.splitlines()[0]
