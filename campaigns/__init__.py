"""The shipped campaign files (``ftcsim campaign li2023_methods ...`` finds them by name); a package only so
that a wheel installs them beside the code (pyproject.toml package data)."""
