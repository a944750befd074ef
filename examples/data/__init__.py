"""Example data shipped with simgap as ``simgap.example_data`` (see README.md in this folder)."""
