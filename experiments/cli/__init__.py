"""The `playroom` command line."""
