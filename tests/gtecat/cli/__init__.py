"""CLI tests: demo, run, slaves/pdos/sdo, newcomer errors (issue 8)."""
