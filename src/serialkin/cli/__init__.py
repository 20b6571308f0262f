"""The ``serialkin`` command line (click)."""
