"""000's designed gains, solved once per test session: the observer and controller designs (about
5 s each) and the files `ftcsim design li2023-observer|li2023-controller` writes, kept in the session's
shared temporary root under a file lock, so every pytest-xdist worker and test module reads the same."""
import fcntl
import pickle

import pytest

from orchestrator.common.jsonio import write_json_atomic
from papers.p000_li2023 import design_controller as dc
from papers.p000_li2023 import design_observer as de

DESIGNS = {"observer": de.design, "controller": dc.design}


@pytest.fixture(scope="session")
def li2023_designs(tmp_path_factory):
    """{"observer": (design result, JSON file), "controller": (design result, JSON file)}."""
    root = tmp_path_factory.getbasetemp().parent  # shared by the xdist workers of this session
    folder = root / "li2023-designs"
    folder.mkdir(exist_ok=True)
    out = {}
    with open(root / "li2023-designs.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        for which, design in DESIGNS.items():
            path, kept = folder / f"{which}.json", folder / f"{which}.pickle"
            if not kept.is_file():
                r = design()
                write_json_atomic(path, r)  # what `ftcsim design` writes
                kept.write_bytes(pickle.dumps(r))
            out[which] = (pickle.loads(kept.read_bytes()), path)
    return out
