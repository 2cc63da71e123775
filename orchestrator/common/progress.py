"""Progress of a long command on stderr, the same in every command: a tqdm bar when stderr is a
terminal; otherwise (a log file, a pipe, a batch job's ``.out``) no ``\\r`` at all, one plain line
through :mod:`logging` every ``every`` seconds and one at the end (logger ``ftcsim.progress`` unless
another is given).

    with Progress(20000, "li2023_fasmc", unit="step") as p:
        for k in ...:
            p.update(1)
"""
from __future__ import annotations

import logging
import sys
import time

__all__ = ["Progress", "is_terminal"]


def is_terminal(stream) -> bool:
    """True if ``stream`` is an interactive terminal (False for files, pipes and closed streams)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


class Progress:
    """``total`` items (``unit``: "step", "run") of ``name``.

    ``delay``: seconds before a bar first shows (short runs show none); ``leave``: keep the bar once
    done; ``every``: seconds between plain lines when stderr is no terminal (0: only the last line;
    the last line is written only when at least one line was, or the work took ``every`` seconds);
    ``logger``: where plain lines go; ``final_line``: always end with a plain line."""

    def __init__(self, total: int, name: str, unit: str = "step", *, delay: float = 2.0, leave: bool = False,
                 every: float = 30.0, logger: str = "ftcsim.progress", enabled: bool = True, smoothing: float = 0.3,
                 final_line: bool = False):
        self.total, self.name, self.unit, self.every = int(total), str(name), unit, float(every)
        self.final_line = final_line
        self.done = 0
        self.postfix: dict = {}
        self.t0 = self.last = time.monotonic()
        self.lines = 0
        self.log = logging.getLogger(logger)
        self.bar = None
        self.plain = bool(enabled) and self.total > 0 and not is_terminal(sys.stderr)
        if enabled and self.total > 0 and not self.plain:
            from tqdm import tqdm

            self.bar = tqdm(total=self.total, desc=self.name, unit=unit, file=sys.stderr, dynamic_ncols=True,
                            delay=delay, leave=leave, mininterval=0.5, smoothing=smoothing)

    def update(self, n: int = 1, **postfix) -> None:
        """``n`` more items done; ``postfix`` (e.g. ``failed=2``) is shown beside the count."""
        self.done += n
        if postfix:
            self.postfix.update(postfix)
        if self.bar is not None:
            self.bar.update(n)
            if postfix:
                self.bar.set_postfix(self.postfix, refresh=False)
        elif self.plain and self.every > 0 and time.monotonic() - self.last >= self.every:
            self.line()

    def line(self) -> None:
        """One plain line: done of total, rate and the time left."""
        now = time.monotonic()
        self.last = now
        self.lines += 1
        elapsed = now - self.t0
        rate = self.done / elapsed if elapsed > 0 else 0.0
        left = (f", about {(self.total - self.done) / rate:.0f} s left" if rate > 0 and self.done < self.total else "")
        extra = "".join(f" ({v} {k})" for k, v in self.postfix.items())
        self.log.info("%s: %d of %d %ss done%s in %.0f s, %.3g %ss/s%s", self.name, self.done, self.total, self.unit,
                      extra, elapsed, rate, self.unit, left)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None
        elif self.plain and (self.final_line or self.lines or (self.every > 0 and time.monotonic() - self.t0 >= self.every)):
            self.plain = False
            self.line()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
