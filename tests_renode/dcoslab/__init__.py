"""The DCOS emulator lab: board definitions and emulator control for the tests and `make run`."""
