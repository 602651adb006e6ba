"""Studies of any scene file: maps of outcomes over any scene keys (`sweep`) and scene keys
identified from measurements (`fit`). The rod's regime map runs on the same machinery
(`runner`). Imported lazily: `nr.sweep`, `nr.fit`."""
from __future__ import annotations


def sweep(*args, **kwargs):
    from .maps import sweep as _sweep

    return _sweep(*args, **kwargs)


def fit(*args, **kwargs):
    from .fitting import fit as _fit

    return _fit(*args, **kwargs)


sweep.__doc__ = "Map outcomes of a scene file over axes of scene keys; see nonsmooth_rod.studies.maps.sweep."
fit.__doc__ = "Estimate scene keys from measured events and/or a trajectory; see nonsmooth_rod.studies.fitting.fit."
