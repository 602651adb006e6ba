"""Results of any scene as files and tables: trajectory.csv, summary.json, the scene file's copy.

    save(result, "out/")        # trajectory.csv, summary.json (schema nonsmooth-rod/summary/2), scene copy
    result = load("out/")       # the same SimulationResult back (floats bit for bit), scene_file attached
    df = to_dataframe(result)   # pandas (optional extra): one tidy column per quantity
    again = restart("out/", t_end=2.0)          # go on exactly from the saved end state
    again = restart("out/", t=0.5, t_end=1.0)   # or from (q, v) of the last sample at or before t

Column names are `<body>.<quantity>` and `<contact>.<quantity>` (docs/output-format.md). A result
made by `scenefile.simulate_scene` carries `result.scene_file`, which gives the names; otherwise
bodies keep their `RigidBody.name` (body0, body1, ... where names repeat) and contacts theirs.

One run's files belong together: summary.json, written last, holds the run's id and the sha256
of every file it describes, so `load` refuses a folder where a killed run replaced the
trajectory but not the summary. Temporary files a killed run left are removed by the next save.
"""
from __future__ import annotations

import hashlib
import math
import uuid
from pathlib import Path

import numpy as np

from .io import file_digest, provenance, read_csv, remove_stale_temps, write_csv, write_json, write_text
from .results import Event, Impact, Phase, SimulationResult, Trajectory
from .validation import InputError

SUMMARY_SCHEMA = "nonsmooth-rod/summary/2"
ROD_SUMMARY_SCHEMA = "nonsmooth-rod/summary/1"  # `simulate`'s summary of the paper's rod (rod/simulation.py)
BODY_QUANTITIES = ("x", "y", "theta", "vx", "vy", "omega")  # m, m, rad, m/s, m/s, rad/s
CONTACT_QUANTITIES = ("N", "T", "mode")  # N, N, word


def body_names_of(result) -> list[str]:
    sf = getattr(result, "scene_file", None)
    if sf is not None:
        return list(sf.body_names)
    n = result.trajectory.q.shape[1] // 3
    setup = getattr(result, "setup", None)
    scene = setup.scene if setup is not None else None
    names = [str(b.name) for b in scene.bodies] if scene is not None and len(scene.bodies) == n else []
    # Names become column prefixes: they must be distinct and not clash with the fallback ones.
    if len(set(names)) == n and all(name and name.isprintable() and "." not in name for name in names):
        return names
    return [f"body{i}" for i in range(n)]


def trajectory_columns(result) -> dict:
    """Ordered columns of trajectory.csv: t, q and v of every body, N, T, mode of every contact, the
    reactions of every joint."""
    tr = result.trajectory
    cols = {"t": np.asarray(tr.t, dtype=float)}
    for i, name in enumerate(body_names_of(result)):
        for j, qty in enumerate(BODY_QUANTITIES):
            source = tr.q if j < 3 else tr.v
            cols[f"{name}.{qty}"] = source[:, 3 * i + j % 3]
    for k, name in enumerate(result.contact_names):
        cols[f"{name}.N"] = tr.normal_force[:, k]
        cols[f"{name}.T"] = tr.tangential_force[:, k]
        cols[f"{name}.mode"] = [str(m) for m in tr.modes[:, k]]
    for name, reactions in (getattr(result, "joint_forces", None) or {}).items():
        for what, values in reactions.items():  # a pin's Fx, Fy; a slider's F, M (model/joints.py)
            cols[f"{name}.{what}"] = np.asarray(values, dtype=float)
    return cols


def _by_name(names, values) -> dict:
    return {n: np.asarray(values, dtype=float)[3 * i:3 * i + 3].tolist() for i, n in enumerate(names)}


def _impact_dict(imp: Impact, bodies, contacts) -> dict:
    return {"t": float(imp.t), "contact": imp.contact, "q": _by_name(bodies, imp.q),
            "v_before": _by_name(bodies, imp.v_before), "v_after": _by_name(bodies, imp.v_after),
            "normal_impulse": dict(zip(contacts, np.asarray(imp.normal_impulse, float).tolist())),
            "tangential_impulse": dict(zip(contacts, np.asarray(imp.tangential_impulse, float).tolist()))}


def _scene_block(result) -> dict:
    sf = getattr(result, "scene_file", None)
    block = {"bodies": body_names_of(result), "contacts": list(result.contact_names)}
    if sf is not None:
        block.update(file=sf.source, title=sf.title, lines=sf.line_names, forces=sf.force_names,
                     shapes=sf.shapes, overrides=list(sf.overrides),
                     sha256=hashlib.sha256(sf.text.encode()).hexdigest() if sf.text else None)
    return block


def _plain(value):
    """A JSON-able copy of an option's value (a callable stop condition by its name)."""
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (bool, int, float, str)) or value is None:
        return value
    if isinstance(value, (np.floating, np.integer, np.ndarray)):
        return value.tolist()
    if hasattr(value, "contact"):  # StopAtImpact
        return value.contact
    return getattr(value, "__qualname__", None) or repr(value)


def _law_data(law) -> dict:
    return {"mu_s": law.friction.mu_s, "mu_d": law.friction.mu_d, "restitution": law.impact.restitution}


def _body_rows_data(row: dict, bodies) -> dict:
    """A linear relation's or joint's row {body index: coefficients} as the scene file has it."""
    return {bodies[b]: list(w) for b, w in row.items()}


def _contact_data(contact, bodies, lines, segments) -> dict:
    law = _law_data(contact.law)
    if hasattr(contact, "gap0"):  # a LinearRelation
        return {"name": contact.name, "kind": "linear", "gap0": contact.gap0,
                "normal": _body_rows_data(contact.normal, bodies), "tangent": _body_rows_data(contact.tangent, bodies),
                "tangent_velocity": contact.tangent_velocity, "law": law}
    if hasattr(contact, "body_a"):
        return {"name": contact.name, "kind": "disk-on-disk", "body_a": bodies[contact.body_a],
                "body_b": bodies[contact.body_b], "radius_a": contact.radius_a, "radius_b": contact.radius_b,
                "offset_a": list(contact.offset_a), "offset_b": list(contact.offset_b), "law": law}
    if hasattr(contact, "segment"):
        return _segment_contact_data(contact, bodies, segments, law)
    if hasattr(contact, "vertex_body"):  # a VertexOnEdge (found between shapes), described; null: fixed
        return {"name": contact.name, "kind": "vertex-on-edge", "law": law,
                "vertex_body": bodies[contact.vertex_body] if contact.vertex_body >= 0 else None,
                "edge_body": bodies[contact.edge_body] if contact.edge_body >= 0 else None,
                **{k: _plain(getattr(contact, k)) for k in ("vertex", "edge_start", "edge_end", "cone", "radius",
                                                            "tie_wins")},
                "depth_limit": contact.depth_limit if math.isfinite(contact.depth_limit) else None,
                "neighbours": _plain(contact.neighbours)}
    line = contact.line
    name = next((n for n, known in lines.items() if known == line), f"line{len(lines)}")
    lines[name] = line
    kind = "disk-on-line" if contact.radius > 0 else "point-on-line"
    data = {"name": contact.name, "kind": kind, "body": bodies[contact.body], "line": name,
            "offset": list(contact.offset), "law": law}
    return data | ({"radius": contact.radius} if contact.radius > 0 else {})


def _segment_contact_data(contact, bodies, segments, law) -> dict:
    """A disk or point on a segment, or a segment's end on an edge; its segment kept by name in `segments`."""
    segment = contact.segment
    name = next((n for n, known in segments.items() if known == segment), segment.name)
    while name in segments and segments[name] != segment:
        name += "+"
    segments[name] = segment
    if hasattr(contact, "edge_start"):
        return {"name": contact.name, "kind": "segment-end-on-edge", "body": bodies[contact.body], "segment": name,
                "end": contact.end, "edge_start": list(contact.edge_start), "edge_end": list(contact.edge_end),
                "law": law}
    kind = "disk-on-segment" if contact.radius > 0 else "point-on-segment"
    data = {"name": contact.name, "kind": kind, "body": bodies[contact.body], "segment": name,
            "offset": list(contact.offset), "law": law}
    return data | ({"radius": contact.radius} if contact.radius > 0 else {})


def _motion_data(motion) -> dict:
    """{"motion": ...} of a driven line, segment or body, in the scene file's layout ({} for none)."""
    from .model.motion import Harmonic, Tabulated

    if motion is None:
        return {}
    if isinstance(motion, Harmonic):
        return {"motion": {"kind": "harmonic", "amplitude": list(motion.amplitude),
                           "frequency_hz": motion.frequency_hz, "phase_deg": math.degrees(motion.phase)}}
    if isinstance(motion, Tabulated):
        return {"motion": {"kind": "table", "times": list(motion.times),
                           "positions": [list(p) for p in motion.positions]}
                | ({"interpolation": motion.interpolation} if motion.interpolation != "linear" else {})}
    return {"motion": {"kind": "python", "function": _plain(motion.function)}}


def _force_data(force, bodies) -> dict:
    import dataclasses

    data = {k: _plain(v) for k, v in dataclasses.asdict(force).items()}
    if hasattr(force, "row"):  # a LinearJoint
        data["row"] = _body_rows_data(force.row, bodies)
    for key in ("body", "body_a", "body_b"):
        if data.get(key) is not None:
            data[key] = bodies[data[key]]
    return {"kind": type(force).__name__, **data}


def scene_description(result) -> dict | None:
    """The scene and start of a run made through `nr.simulate` (no scene file), in the scene
    file's layout (docs/scene-format.md): bodies, lines, contacts, forces, initial state."""
    inputs = getattr(result, "setup", None)
    if inputs is None:
        return None
    scene, bodies = inputs.scene, body_names_of(result)
    lines: dict = {}
    segments: dict = {}
    contacts = [_contact_data(c, bodies, lines, segments) for c in scene.contacts]
    q0, v0 = np.asarray(inputs.q0, float), np.asarray(inputs.v0, float)
    driven = {d.body: d.motion for d in getattr(scene, "driven", ())}
    return {
        "gravity": scene.gravity,
        "bodies": [{"name": n, "mass": b.mass, "inertia": b.inertia} | _motion_data(driven.get(i))
                   for i, (n, b) in enumerate(zip(bodies, scene.bodies))],
        "lines": [{"name": n, "point": list(line.point), "angle_deg": math.degrees(line.angle),
                   "velocity": line.velocity} | _motion_data(line.motion) for n, line in lines.items()],
        **({"segments": [{"name": n, "a": list(s.a), "b": list(s.b)} | _motion_data(s.motion)
                         for n, s in segments.items()]} if segments else {}),
        "contacts": contacts, "forces": [_force_data(f, bodies) for f in scene.forces],
        "joints": [_force_data(j, bodies) for j in getattr(scene, "joints", ())],
        "applied_force": _plain(scene.applied_force),
        "initial": {n: {"q": q0[3 * i:3 * i + 3].tolist(), "v": v0[3 * i:3 * i + 3].tolist()}
                    for i, n in enumerate(bodies)},
    }


def _run_options(result) -> dict:
    sf = getattr(result, "scene_file", None)
    if sf is not None:
        return {**sf.options, "t_end": sf.t_end, "stop": sf.stop, "save_every": sf.save_every}
    setup = getattr(result, "setup", None)
    if setup is None:
        return {}
    return {**_plain(setup.options), **{k: _plain(getattr(setup, k)) for k in ("t0", "t_end", "save_every", "stop")}}


def summary_dict(result, command=None) -> dict:
    sf = getattr(result, "scene_file", None)
    bodies, contacts = body_names_of(result), list(result.contact_names)
    return {
        "schema": SUMMARY_SCHEMA, "run_id": uuid.uuid4().hex, "scene": _scene_block(result),
        "params": sf.data if sf is not None else scene_description(result),
        "method": result.method,
        "options": _run_options(result),
        "status": str(getattr(result.status, "value", result.status)), "message": result.message,
        "success": bool(result.success),
        "phases": {c: [ph.as_dict() for ph in result.phases.get(c, [])] for c in contacts},
        "impacts": [_impact_dict(i, bodies, contacts) for i in result.impacts],
        "events": [{"t": float(e.t), "kind": e.kind, "contact": e.contact, "detail": e.detail} for e in result.events],
        "steps": int(getattr(result, "steps", 0)), "cpu_time_s": float(getattr(result, "cpu_time_s", 0.0)),
        "stats": dict(result.stats), "provenance": provenance(command),
        "end_state": _end_state_dict(result),
    }


def _end_state_dict(result):
    """What the run's next step would read (result.end_state), for an exact restart; None when the
    method keeps nothing beyond (q, v) or the run failed."""
    state = getattr(result, "end_state", None)
    return None if state is None else state.as_dict()


def scene_copy_name(sf) -> str:
    return "scene.json" if str(sf.source).lower().endswith(".json") else "scene.toml"


def save(result, out_dir, command=None) -> dict:
    """Write trajectory.csv, summary.json and (for a scene-file run) the scene file's copy; returns
    the summary. summary.json comes last and records the others' sha256 (see the module doc)."""
    out_dir = Path(out_dir)
    remove_stale_temps(out_dir)
    summary = summary_dict(result, command)
    written = [out_dir / "trajectory.csv"]
    write_csv(written[0], trajectory_columns(result))
    sf = getattr(result, "scene_file", None)
    if sf is not None and sf.text:
        written.append(out_dir / scene_copy_name(sf))
        write_text(written[-1], sf.text)
    write_summary(out_dir, summary, written)
    return summary


def write_summary(out_dir, summary: dict, written) -> None:
    """summary.json, last, with the sha256 of the files of the run it describes (`check_files`)."""
    summary.setdefault("run_id", uuid.uuid4().hex)
    summary["files"] = {Path(path).name: {"sha256": file_digest(path)} for path in written}
    write_json(Path(out_dir) / "summary.json", summary)


def check_files(folder: Path, summary: dict, run_kind: str = "run") -> None:
    """Refuse a folder whose files are not the ones its summary.json describes (a run killed
    between writing them, or a file replaced by hand), in one line."""
    for name, record in (summary.get("files") or {}).items():
        path = folder / name
        try:
            same = file_digest(path) == record.get("sha256")
        except OSError as err:
            raise InputError(f"{path}: cannot read ({err.strerror or err})") from None
        if not same:
            raise InputError(f"{folder}: mixed results: {name} is not the file summary.json describes "
                             f"(run {summary.get('run_id', '?')}); a {run_kind} was interrupted or the file "
                             "was changed: run it again into this folder")


# ------------------------------------------------------------------ which command wrote a folder
# `simulate` (the paper's rod) and `run` (any scene file) both write trajectory.csv and
# summary.json, by default into ./results: the summary's schema tells them apart, so that each
# reader says what it got, and no writer silently replaces the other's results.
_KIND_OF_SCHEMA = {ROD_SUMMARY_SCHEMA: "simulate", SUMMARY_SCHEMA: "run"}
_KIND_TEXT = {"simulate": "the results of `nonsmooth-rod simulate` (the paper's rod)",
              "run": "the results of `nonsmooth-rod run` (a scene file)",
              "sweep": "a sweep of `nonsmooth-rod sweep`",
              "unknown": "a summary.json this program did not write"}


def folder_kind(folder) -> str | None:
    """"simulate", "run", "sweep", "unknown" (a summary.json of something else) or None (no results)."""
    import json

    folder = Path(folder)
    if (folder / "sweep.json").is_file():
        return "sweep"
    try:
        schema = json.loads((folder / "summary.json").read_text(encoding="utf-8")).get("schema")
    except FileNotFoundError:
        return None
    except (OSError, ValueError, AttributeError):
        return "unknown"
    return _KIND_OF_SCHEMA.get(schema, "unknown")


def describe_folder(folder) -> str:
    return _KIND_TEXT.get(folder_kind(folder), "no results")


def claim_folder(folder, kind: str, force: bool = False) -> None:
    """Before `kind` ("simulate" or "run") writes into `folder`: refuse, in one line, to replace
    the results of another command there unless `force`."""
    found = folder_kind(folder)
    if found is None or found == kind or force:
        return
    raise InputError(f"--out {folder} holds {_KIND_TEXT[found]}; `nonsmooth-rod {kind}` would overwrite "
                     "them: choose another --out, or add --force to replace them")


def _read_summary(folder: Path) -> dict:
    import json

    path = folder / "summary.json"
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{folder}: no summary.json here (not a results folder of `nonsmooth-rod run`)") from None
    except (OSError, ValueError) as err:
        raise InputError(f"{path}: cannot read: {err}") from None
    if not isinstance(summary, dict) or summary.get("schema") != SUMMARY_SCHEMA:
        kind = folder_kind(folder)
        hint = (f"; draw it with `nonsmooth-rod plot {folder}`" if kind == "simulate" else "")
        raise InputError(f"{folder} holds {_KIND_TEXT.get(kind, 'no results')}, not those of "
                         f"`nonsmooth-rod run` (summary schema {SUMMARY_SCHEMA}){hint}")
    return summary


def _trajectory_from(cols: dict, bodies, contacts) -> Trajectory:
    def stack(quantities):
        return np.column_stack([cols[f"{b}.{q}"] for b in bodies for q in quantities])

    q, v = stack(BODY_QUANTITIES[:3]), stack(BODY_QUANTITIES[3:])
    n = len(cols["t"])
    forces = {qty: (np.column_stack([cols[f"{c}.{qty}"] for c in contacts]) if contacts else np.zeros((n, 0)))
              for qty in ("N", "T")}
    modes = (np.column_stack([np.asarray(cols[f"{c}.mode"], dtype=object) for c in contacts])
             if contacts else np.zeros((n, 0), dtype=object))
    return Trajectory(cols["t"], q, v, np.full_like(q, np.nan), forces["N"], forces["T"], modes)


def _vector_of(by_name: dict, names) -> np.ndarray:
    return np.concatenate([np.asarray(by_name[n], dtype=float) for n in names]) if names else np.zeros(0)


def _impact_from(d: dict, bodies, contacts) -> Impact:
    return Impact(d["t"], d["contact"], _vector_of(d["q"], bodies), _vector_of(d["v_before"], bodies),
                  _vector_of(d["v_after"], bodies), np.array([d["normal_impulse"][c] for c in contacts]),
                  np.array([d["tangential_impulse"][c] for c in contacts]))


def load(folder):
    """The SimulationResult saved in `folder` by save(); `scene_file` attached when the copy is there."""
    from .scenefile import load_scene

    folder = Path(folder)
    summary = _read_summary(folder)
    check_files(folder, summary)
    bodies, contacts = summary["scene"]["bodies"], summary["scene"]["contacts"]
    try:
        cols = read_csv(folder / "trajectory.csv")
        trajectory = _trajectory_from(cols, bodies, contacts)
    except (OSError, KeyError, ValueError, IndexError) as err:
        raise InputError(f"{folder / 'trajectory.csv'}: cannot read the trajectory ({err})") from None
    result = SimulationResult(
        summary["method"], summary["status"], summary["message"], trajectory, list(contacts),
        events=[Event(e["t"], e["kind"], e["contact"], e["detail"]) for e in summary["events"]],
        impacts=[_impact_from(d, bodies, contacts) for d in summary["impacts"]],
        phases={c: [Phase(p["mode"], p["t_start"], p["t_end"]) for p in summary["phases"][c]] for c in contacts},
        steps=summary["steps"], cpu_time_s=summary["cpu_time_s"], stats=summary["stats"])
    result.end_state = _end_state_from(summary.get("end_state"), len(bodies) * 3, len(contacts), folder)
    copies = [folder / n for n in ("scene.toml", "scene.json") if (folder / n).exists()]
    result.scene_file = load_scene(copies[0], summary["scene"].get("overrides", ())) if copies else None
    result.joint_forces = _joint_forces_from(cols, result.scene_file)
    return result


def _joint_forces_from(cols: dict, sf) -> dict:
    """The joints' reaction columns of trajectory.csv, by the scene file's joints (none without it)."""
    from .model.joints import REACTION_NAMES

    joints = sf.scene.joints if sf is not None else ()
    return {j.name: {what: np.asarray(cols[f"{j.name}.{what}"], dtype=float) for what in REACTION_NAMES[j.kind]}
            for j in joints if all(f"{j.name}.{what}" in cols for what in REACTION_NAMES[j.kind])}


def _end_state_from(d, n_dof: int, n_contacts: int, folder):
    if d is None:
        return None
    from .integrators.moreau_jean_records import ResumeState

    try:
        return ResumeState.from_dict(d, n_dof, n_contacts)
    except (KeyError, TypeError, ValueError) as err:
        raise InputError(f"{folder / 'summary.json'}: end_state: cannot read it ({err})") from None


def to_dataframe(result):
    """The trajectory as a pandas DataFrame, columns as in trajectory.csv (needs pandas)."""
    try:
        import pandas as pd
    except ImportError:
        raise InputError("to_dataframe needs pandas: pip install pandas") from None
    return pd.DataFrame(trajectory_columns(result))


def restart(source, t: float | None = None, t_end: float | None = None):
    """Run on from a result (a results folder, a loaded result or one made by `nr.simulate`) up to
    `t_end` (default: the scene file's t_end), with the same scene, method and settings.

    Without `t` (or with t at or after the last sample) it goes on from the end state the run
    saved — for Moreau–Jean with the contact memory and the step grid, so run(0→T) and
    run(0→T/2) then restart(T/2→T) agree bit for bit; from an earlier `t`, from the state (q, v)
    of the last sample at or before t."""
    result = load(source) if isinstance(source, (str, Path)) else source
    scene, method, options, stop, save_every = _setup_of(result)
    times = np.asarray(result.trajectory.t)
    k = len(times) - 1 if t is None else int(np.searchsorted(times, t, side="right")) - 1
    if k < 0:
        raise InputError(f"restart time t = {t!r} precedes the saved run (starts at {times[0]:g} s)")
    sf = getattr(result, "scene_file", None)
    if t_end is None and sf is None:
        raise InputError("restart needs t_end (the result has no scene file to take it from)")
    t0, t_end = float(times[k]), float(sf.t_end if t_end is None else t_end)
    if t_end <= t0:
        raise InputError(f"t_end = {t_end:g} s must exceed the restart time {t0:g} s")
    q0, v0 = result.trajectory.q[k].copy(), result.trajectory.v[k].copy()
    resume = getattr(result, "end_state", None) if k == len(times) - 1 else None
    from .driver import simulate

    again = simulate(scene, q0, v0, t_end, method, t0=t0, save_every=save_every, stop=stop, resume=resume,
                     **options)
    again.scene_file = sf
    return again


def _setup_of(result):
    """(scene, method, options, stop, save_every) a result was run with."""
    setup = getattr(result, "setup", None)
    if setup is not None:
        return setup.scene, setup.method, setup.options, setup.stop, setup.save_every
    sf = getattr(result, "scene_file", None)
    if sf is None:
        raise InputError("restart needs the scene: a results folder with its scene copy, a scene-file run or "
                         "a result of nr.simulate")
    return sf.scene, sf.method, dict(sf.options), list(sf.stop) or None, sf.save_every
