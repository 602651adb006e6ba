"""What one run of a scene did, as a row of a map: each contact's phase sequence, the first
slip, stick, lift-off and impact times, whether the scene held, the final state and the status.
The regime is the phase sequence of every contact (same sequence, same regime)."""
from __future__ import annotations

import math

import numpy as np

from ..results import SLIP_STATES

EVENT_KINDS = ("slip", "stick", "lift-off", "impact")


def _kind_of_start(mode: str) -> str | None:
    """The event a phase of `mode` starts with (a phase after another one)."""
    if mode in SLIP_STATES:
        return "slip"
    return {"stick": "stick", "open": "lift-off"}.get(mode)


def contact_events(result) -> list[tuple[str, str, float]]:
    """(kind, contact, t) of every switch, time-ordered: a slip, stick or lift-off where a phase
    of that kind begins after another phase (a slip from the start counts at t = 0), an impact
    where the run located one."""
    events = []
    for name, phases in result.phases.items():
        for i, ph in enumerate(phases):
            kind = _kind_of_start(ph.mode)
            if kind is None or (i == 0 and kind != "slip"):
                continue
            if i > 0 and kind == "slip" and phases[i - 1].mode in SLIP_STATES:
                continue  # a reversal of the slip direction is not an onset
            events.append((kind, name, float(ph.t_start)))
    events += [("impact", str(imp.contact), float(imp.t)) for imp in result.impacts]
    return sorted(events, key=lambda e: e[2])


def regime_of(result) -> str:
    """'contact: mode mode ...; contact: ...' — the phase sequence of every contact."""
    return "; ".join(f"{name}: {' '.join(ph.mode for ph in result.phases.get(name, [])) or '-'}"
                     for name in result.contact_names)


def held(result) -> bool:
    """Every contact stuck (closed, not slipping) for the whole run."""
    return bool(result.success and all(
        [ph.mode for ph in result.phases.get(name, [])] == ["stick"] for name in result.contact_names))


def outcome_columns(contact_names, n_dof: int) -> tuple:
    firsts = tuple(f"{c}.first_{k.replace('-', '_')}" for c in contact_names for k in EVENT_KINDS)
    return ("regime", "status", "held") + firsts + tuple(f"q_end.{i}" for i in range(n_dof)) + (
        tuple(f"v_end.{i}" for i in range(n_dof)) + ("t_end", "message"))


def outcome_row(result, contact_names) -> dict:
    """The outcome columns of one run (NaN where an event never happened)."""
    row = {"regime": regime_of(result), "status": str(result.status), "held": float(held(result))}
    firsts = {}
    for kind, contact, t in contact_events(result):
        firsts.setdefault(f"{contact}.first_{kind.replace('-', '_')}", t)
    for c in contact_names:
        for k in EVENT_KINDS:
            key = f"{c}.first_{k.replace('-', '_')}"
            row[key] = firsts.get(key, math.nan)
    q, v = np.asarray(result.q)[-1], np.asarray(result.v)[-1]
    row |= {f"q_end.{i}": float(x) for i, x in enumerate(q)} | {f"v_end.{i}": float(x) for i, x in enumerate(v)}
    row |= {"t_end": float(result.t[-1]), "message": " ".join(str(result.message).split())[:200]}
    return row


def refused_row(contact_names, n_dof: int, status: str, message: str) -> dict:
    """The row of a point the scene refused (μd > μs, ...) or whose run raised."""
    row = {c: math.nan for c in outcome_columns(contact_names, n_dof)}
    return row | {"regime": status, "status": status, "message": " ".join(message.split())[:200]}
