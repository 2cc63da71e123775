"""Errors the command line turns into one clear message and an exit status."""


class InputError(Exception):
    """Bad input: a scenario, parameter, FMU file or CLI argument. Exit status 2.

    ``source`` names the file (or 'command line'), ``key`` the offending key, ``problem``
    what is wrong. ``str()`` gives the one-line message shown to the user."""

    def __init__(self, source, key, problem):
        self.source, self.key, self.problem = str(source), str(key), str(problem)
        super().__init__(f"{self.source}: {self.key}: {self.problem}")


class SimulationError(Exception):
    """A run failed after it started (an FMU returned an error). Exit status 1."""
