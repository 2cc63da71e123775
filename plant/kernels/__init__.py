"""The plant's own compiled kernels (flexible spacecraft, rigid spacecraft with wheels, T-S attitude
model) and ``common.py``, the scalar helpers every kernel shares; the estimators' and controllers'
kernels lie beside their blocks (``estimator/kernels/``, ``controller/kernels/``). How kernels are
written, switched and cached: ``plant/jit.py``.

``from plant import kernels; kernels.enabled()`` keeps working: the switch is re-exported here."""
from plant.jit import OPTIONAL_IMPORTS, REASON, cache_root, enabled, jit, numba, set_enabled  # noqa: F401
