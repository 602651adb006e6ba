"""What the compiled loop's typing asks its callees for, and the shares file written from it.

Used by `python -m nonsmooth_rod._loop_callees` (after an edit that changes a callee of
the loop or its arguments) and by tests/engine/test_compile_split.py (that the shipped shares are
still what the loop asks for). Not used by a run: it reaches into numba's compiler (a pipeline
stopped after type inference) to type the chain's functions without compiling them, which takes
~6 s of CPU where their callees are cached.
"""
from __future__ import annotations

from pathlib import Path

from ._compile_split import CHAIN, HELPER_SHARE, _function

SHARES_FILE = Path(__file__).resolve().parent / "_compile_shares.py"


def _typing_only_compiler():
    """numba's pipeline cut after type inference (its early completion returns the typemap)."""
    from numba.core import compiler
    from numba.core.compiler_machinery import FunctionPass, register_pass
    from numba.core.typed_passes import NopythonTypeInference

    @register_pass(mutates_CFG=False, analysis_only=True)
    class StopAfterTyping(FunctionPass):
        _name = "nonsmooth_rod_stop_after_typing"

        def __init__(self):
            FunctionPass.__init__(self)

        def run_pass(self, state):
            raise compiler._EarlyPipelineCompletion(state.typemap)

    class TypingOnly(compiler.CompilerBase):
        def define_pipelines(self):
            pm = compiler.DefaultPassBuilder.define_untyped_pipeline(self.state)  # inlines jit_inline's
            pm.add_pass(NopythonTypeInference, "nopython frontend")
            pm.add_pass(StopAfterTyping, "stop after typing")
            pm.finalize()
            return [pm]

    return TypingOnly


def callees_asked(dispatcher, args, pipeline) -> list:
    """[(dispatcher, argument types)] of the dispatchers that typing dispatcher(args) asks for
    itself (inlined functions' calls included; not their callees' own calls)."""
    from numba.core import compiler
    from numba.core import dispatcher as numba_dispatcher

    asked, depth = [], [0]
    template, compile_ = numba_dispatcher.Dispatcher.get_call_template, numba_dispatcher.Dispatcher.compile

    def compile_counted(self, sig):
        depth[0] += 1
        try:
            return compile_(self, sig)
        finally:
            depth[0] -= 1

    def template_recorded(self, call_args, kws):
        if depth[0] == 0:
            asked.append((self, tuple(call_args)))
        return template(self, call_args, kws)

    numba_dispatcher.Dispatcher.get_call_template = template_recorded
    numba_dispatcher.Dispatcher.compile = compile_counted
    try:
        own = dispatcher._compiler
        flags = compiler.Flags()
        own.targetdescr.options.parse_as_flags(flags, own.targetoptions)
        compiler.compile_extra(own.targetdescr.typing_context, own.targetdescr.target_context, dispatcher.py_func,
                               args=tuple(args), return_type=None, flags=own._customize_flags(flags),
                               locals=own.locals, pipeline_class=pipeline)
    finally:
        numba_dispatcher.Dispatcher.get_call_template, numba_dispatcher.Dispatcher.compile = template, compile_
    return asked


def _name(dispatcher) -> tuple[str, str]:
    return dispatcher.py_func.__module__, dispatcher.py_func.__qualname__


def loop_callees(entry_args) -> list[tuple[str, str, tuple]]:
    """Sorted (module, function, argument types) of every package function the chain's typing
    asks for, outside the chain, from the loop's entry (`run_steps`) typed with `entry_args`."""
    pipeline = _typing_only_compiler()
    todo, typed, found = [(CHAIN[0], tuple(entry_args))], set(), set()
    while todo:
        name, args = todo.pop()
        if (name, args) in typed:
            continue
        typed.add((name, args))
        for callee, callee_args in callees_asked(_function(*name), args, pipeline):
            callee_name = _name(callee)
            if callee_name in CHAIN:
                todo.append((callee_name, callee_args))
            elif _function(*callee_name) is callee:  # not numba's overloads, nor jitable functions' (no dispatcher)
                found.add((*callee_name, callee_args))
    return sorted(found, key=lambda entry: (entry[0], entry[1], str(entry[2])))


def type_text(numba_type) -> str:
    """A numba type as numba's signature text: `float64[:, ::1]` for a C-contiguous writable
    array of numbers, `int64` for a scalar, the constructor (`UniTuple(int64, 2)`) otherwise."""
    from numba.core import types

    if isinstance(numba_type, types.Array) and numba_type.mutable and numba_type.aligned \
            and numba_type.layout in ("C", "A") and isinstance(numba_type.dtype, types.Number):
        dims = [":"] * numba_type.ndim
        if numba_type.layout == "C":
            dims[-1] = "::1"
        return f"{numba_type.dtype}[{', '.join(dims)}]"
    return str(numba_type) if isinstance(numba_type, types.Number) else repr(numba_type)


def signature_text(args) -> str | None:
    """The argument types as text numba reads back (sigutils) to the same types; None where it
    cannot be (a named tuple, a literal: such a callee is compiled with the chain)."""
    from numba.core import sigutils

    text = "(" + ", ".join(type_text(t) for t in args) + ("," if len(args) == 1 else "") + ")"
    try:
        read_back = tuple(sigutils.normalize_signature(text)[0])
    except Exception:  # noqa: BLE001 — a repr that is no expression of numba.types
        return None
    return text if read_back == tuple(args) else None


def sources_key(root: Path | None = None) -> str:
    """What the shares are written from: a digest of every source of the package but the shares
    file itself (the loop's code, its callees, and the Python that builds its arguments) and the
    numba version that types them. While a shipped file's key is this key, typing the loop again
    can only give the file back."""
    import hashlib

    import numba

    root = SHARES_FILE.parent if root is None else root
    digest = hashlib.blake2b(numba.__version__.encode(), digest_size=16)
    for path in sorted(p for p in root.rglob("*.py") if p.name != SHARES_FILE.name):
        digest.update(str(path.relative_to(root)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def shares_source(callees, key: str) -> str:
    """_compile_shares.py's text: the sources' key, this process's share, then the helper's
    (HELPER_SHARE); the callees whose signature has no text are left out (compiled with the chain)."""
    callees = [(module, name, args) for module, name, args in callees if signature_text(args) is not None]
    shares = ([c for c in callees if c[1] not in HELPER_SHARE], [c for c in callees if c[1] in HELPER_SHARE])
    lines = ['"""The compiled loop\'s callees, compiled on two cores before it (`_compile_split`): the job\'s',
             "share, then the helper's. Each: module, function, the argument types the loop's typing asks",
             "for. Written by `python -m nonsmooth_rod._loop_callees`; do not edit (tests/engine/",
             'test_compile_split.py checks it against the loop, typing the loop again when SOURCES is',
             'not the sources\' key: _loop_callees.sources_key)."""', "", f"SOURCES = {key!r}", "", "SHARES = ("]
    for share in shares:
        lines.append("    (")
        for module, name, args in share:
            lines.append(f"        ({module!r}, {name!r},")
            lines.append(f"         {signature_text(args)!r}),")
        lines.append("    ),")
    lines.append(")")
    return "\n".join(lines) + "\n"


def entry_args():
    """run_steps' argument types, from a tiny compiled run (the loop compiled or loaded first)."""
    from ._compile_job import warm_up

    warm_up()
    (args,) = _function(*CHAIN[0]).signatures
    return args


def write_shares() -> None:
    from .io import write_text

    write_text(SHARES_FILE, shares_source(loop_callees(entry_args()), sources_key()))
    print(f"wrote {SHARES_FILE}")


if __name__ == "__main__":
    write_shares()
