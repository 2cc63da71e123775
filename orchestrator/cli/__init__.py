"""The command line ``ftcsim`` (floor 6): argparse only, each command a few lines over the API
(:mod:`orchestrator.api`) and the library. ``main`` holds the parser and build, validate, scenarios
and run; the other modules each ``register(subparsers)`` their commands."""
