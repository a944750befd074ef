"""`simgap inspect` on a generated FMU with 20,000 variables (target: under 2 s).

    python benchmarks/inspect_large.py [--variables 20000] [--repeats 5]

Writes a modelDescription.xml of ``--variables`` scalar Real variables (parameters with units,
start values and descriptions, outputs, locals: the mix a Modelica export has) into an .fmu
archive (no binary: inspect reads only the description), then times, median of ``--repeats``:
  * in process: inspect_model + format_table (reading and formatting, no interpreter start);
  * CLI:        `simgap inspect MODEL` as a user runs it (interpreter start and imports included),
                full table and filtered (`--causality parameter --name wall*`).
Wall time with CPU time beside it; the machine is shared, so the load average is printed too.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

CAUSALITIES = [("parameter", "fixed", ' start="{start}"'), ("output", "continuous", ""), ("local", "continuous", "")]


def write_fmu(folder: Path, count: int) -> Path:
    rows = []
    for i in range(count):
        causality, variability, start = CAUSALITIES[i % 3]
        rows.append(
            f'  <ScalarVariable name="wall{i // 3}.layer[{i % 7}].T_{i}" valueReference="{i}" causality="{causality}"'
            f' variability="{variability}" description="temperature of layer {i % 7} in wall {i // 3}">'
            f'<Real unit="K"{start.format(start=273.15 + i % 40)}/></ScalarVariable>'
        )
    outputs = "".join(f'<Unknown index="{i + 1}"/>' for i in range(count) if i % 3 == 1)
    xml = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<fmiModelDescription fmiVersion="2.0" modelName="large" guid="{large-inspect}" '
        'generationTool="benchmarks/inspect_large.py" variableNamingConvention="structured">\n'
        ' <CoSimulation modelIdentifier="large"/>\n'
        ' <DefaultExperiment startTime="0" stopTime="86400" stepSize="60"/>\n'
        ' <ModelVariables>\n' + "\n".join(rows) + "\n </ModelVariables>\n"
        f" <ModelStructure><Outputs>{outputs}</Outputs></ModelStructure>\n</fmiModelDescription>\n"
    )
    path = folder / "large.fmu"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("modelDescription.xml", xml)
    return path


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variables", type=int, default=20000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)

    from simgap.inspect import format_table, inspect_model

    with tempfile.TemporaryDirectory() as tmp:
        fmu = write_fmu(Path(tmp), args.variables)
        timings = {"in process": [], "CLI, full table": [], "CLI, filtered": []}
        cpu = {key: [] for key in timings}
        lines = {}
        for _ in range(args.repeats):  # interleaved, so load changes hit every variant alike
            wall, cpu_start = time.perf_counter(), time.process_time()
            info = inspect_model(fmu)
            text = format_table(info["variables"])
            timings["in process"].append(time.perf_counter() - wall)
            cpu["in process"].append(time.process_time() - cpu_start)
            assert info["variable_count"] == args.variables and text.count("\n") == args.variables
            for key, extra in (("CLI, full table", []), ("CLI, filtered", ["--causality", "parameter", "--name", "wall1*"])):
                wall, cpu_start = time.perf_counter(), children_cpu()
                result = subprocess.run([sys.executable, "-m", "simgap.cli", "inspect", str(fmu), *extra],
                                        capture_output=True, text=True, check=True)
                timings[key].append(time.perf_counter() - wall)
                cpu[key].append(children_cpu() - cpu_start)
                lines[key] = result.stdout.count("\n")

    print(f"inspect on a generated FMU with {args.variables} variables, median of {args.repeats} (target < 2 s)")
    for key in timings:
        shown = f", {lines[key]} lines printed" if key in lines else ""
        print(f"  {key:16s} wall {statistics.median(timings[key]):.2f} s  cpu {statistics.median(cpu[key]):.2f} s{shown}")
    worst = max(statistics.median(t) for t in timings.values())
    print(f"  slowest median {worst:.2f} s: {'meets' if worst < 2 else 'MISSES'} the 2 s target")
    print(f"load average (1, 5, 15 min): {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
