"""ftcsim and Basilisk both ways (docs/basilisk.md); needs the optional extra ``ftcsim[basilisk]``::

    from ftcsim.basilisk import FMUModule, BasiliskSpacecraft, conventions
    ctrl = FMUModule("FASMC", 0.01, inputs={"q": "sc.q", "omega": "sc.omega"})   # an FMU as a Basilisk module
    ctrl.scStateInMsg.subscribeTo(scObject.scStateOutMsg)

The parts: :mod:`orchestrator.interop.basilisk` (conventions, module, spacecraft, mission)."""
from orchestrator.interop.basilisk import conventions
from orchestrator.interop.basilisk.mission import Craft, Flight, build_craft, fly
from orchestrator.interop.basilisk.module import PORTS, BridgeError, FMUModule, execute, initialize
from orchestrator.interop.basilisk.spacecraft import BasiliskSpacecraft

__all__ = ["FMUModule", "BridgeError", "PORTS", "initialize", "execute", "BasiliskSpacecraft", "conventions", "Craft",
           "Flight", "build_craft", "fly"]
