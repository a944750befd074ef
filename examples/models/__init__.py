"""Example model sources shipped with simgap as ``simgap.models`` (C sources of FMUs and their
model descriptions, built on first use with :func:`simgap.build_fmu`)."""
