"""A guard on the kernel's speed that cannot flake: reference counting in its step loop.

The step loop (``kernel._steps``) is fast because nothing in it counts references: an
array handed down through an inlined helper, or an early return in one, puts NRT
incref/decref calls into the loop and has made the step up to 2.4 times slower
(docs/benchmarks.md, issue 34). This test compiles the loop afresh (no cache), finds the
basic blocks of its LLVM IR that lie on a cycle of the control-flow graph, and counts the
NRT calls there, for the lumped and the distributed string. The bounds are today's counts
(the calls on the sample-row branch, which runs once per row, and the loops of the delay and
the string); a change that adds one fails here. A new numba may move them: re-measure then.
"""

from __future__ import annotations

import re

import numba
import numpy as np
import pytest

from drill_sim_ros.model import kernel as k
from drill_sim_ros.model.params import DimensionlessParams
from drill_sim_ros.model.presets import load_preset
from drill_sim_ros.model.simulator import SimConfig, Simulator

# NRT calls on the loop's blocks, per string, as of issue 34, with this numba (major.minor);
# distributed 18 -> 20 with the guard's record of an element that gave energy
# (string.step.scatter's branch, taken only then: never in a physical run; the branch-free
# write of both rows at every junction keeps 18 but made the deviated closed loop 8 % slower,
# 91.5 against 84.3 us a period, measured 2026-12-06 with benchmarks/bench_walled_step.py)
MAX_LOOP_NRT_CALLS = {"lumped": 8, "distributed": 20}
MEASURED_WITH_NUMBA = "0.68"
FIG8A = DimensionlessParams(n=6, psi=50.0, beta=0.3, lam=5.0, w0=7.0, omega0=5.0)


def _simulator(kind: str) -> Simulator:
    if kind == "lumped":
        return Simulator(FIG8A, SimConfig(dtau=1e-5), perturb_v=0.01)
    p = load_preset("field_8p5in_shale")
    return Simulator(p.params, SimConfig(dtau=p.dtau), top_drive=p.top_drive, scales=p.scales,
                     string=p.kernel_string)


def _blocks(ir: str) -> dict[str, list[str]]:
    """The basic blocks of the first function defined in ``ir``, by label."""
    body = re.search(r"^define [^\n]*\{\n(.*?)^\}", ir, re.S | re.M).group(1)
    blocks: dict[str, list[str]] = {"entry": []}
    label = "entry"
    for line in body.split("\n"):
        start = re.match(r'^"?([\w.$-]+)"?:', line)
        if start:
            label = start.group(1)
            blocks[label] = []
        else:
            blocks[label].append(line)
    return blocks


def _on_cycles(blocks: dict[str, list[str]]) -> set[str]:
    """The blocks from which a branch leads back to themselves."""
    succ = {b: set(re.findall(r'label %"?([\w.$-]+)"?', "\n".join(lines)))
            for b, lines in blocks.items()}
    found = set()
    for start in blocks:
        seen, todo = set(), list(succ[start])
        while todo:
            b = todo.pop()
            if b == start:
                found.add(start)
                break
            if b not in seen and b in succ:
                seen.add(b)
                todo.extend(succ[b])
    return found


def nrt_calls_on_loops(compiled: numba.core.dispatcher.Dispatcher) -> int:
    """NRT calls on the blocks of the loops of ``compiled``'s one compiled signature."""
    (ir,) = compiled.inspect_llvm().values()
    blocks = _blocks(ir[ir.index("define"):])
    return sum("@NRT_" in line for b in _on_cycles(blocks) for line in blocks[b])


def loop_nrt_calls(kind: str) -> int:
    sim = _simulator(kind)
    fresh = numba.njit(k._steps.py_func)           # compiled here, never from the cache
    out = np.empty((2, k.N_COLS))
    fresh(*sim._kernel_arrays(), out, *sim._wave_arrays(), 1, 1, sim.exact, False)
    return nrt_calls_on_loops(fresh)


def test_the_cycle_finder_sees_a_loop_and_not_a_diamond() -> None:
    ir = ("define i32 @f() {\nentry:\n  br label %head\nhead:\n  call void @NRT_incref(ptr %a)\n"
          "  br i1 %c, label %head, label %exit\nexit:\n  call void @NRT_decref(ptr %a)\n"
          "  ret i32 0\n}\n")
    blocks = _blocks(ir)
    assert _on_cycles(blocks) == {"head"}


@pytest.mark.parametrize("kind", ["lumped", "distributed"])
def test_no_new_reference_counting_in_the_step_loop(kind: str) -> None:
    if not numba.__version__.startswith(MEASURED_WITH_NUMBA + "."):
        pytest.skip(f"the counts were measured with numba {MEASURED_WITH_NUMBA}; re-measure "
                    f"them for numba {numba.__version__} (loop_nrt_calls)")
    calls = loop_nrt_calls(kind)
    assert calls <= MAX_LOOP_NRT_CALLS[kind], (
        f"{calls} NRT calls on the {kind} step loop's blocks, {MAX_LOOP_NRT_CALLS[kind]} "
        "before: an array handed to an inlined helper, or an early return in one? "
        "(docs/contributing.md)")


def _indexed_in_place(a: np.ndarray, n: int) -> float:
    total = 0.0
    for step in range(n):
        for j in range(a.shape[1]):
            total += a[step % a.shape[0], j]
    return total


def _a_copy_per_step(a: np.ndarray, n: int) -> float:   # the mutant: an array per step
    total = 0.0
    for step in range(n):
        row = a[step % a.shape[0]].copy()
        for j in range(row.size):
            total += row[j]
    return total


def test_the_counter_sees_nrt_calls_a_mutant_brings_into_a_loop() -> None:
    """The counter itself can fail: a loop that makes an array every step (NRT allocation
    and reference counting) has NRT calls on its blocks, the same loop indexing in place
    none. (A row view alone, as ``a[i]`` in such a small loop, numba's reference-count
    pruning removes; in the step loop it does not, docs/benchmarks.md, issue 35.)"""
    a = np.arange(6.0).reshape(2, 3)
    plain, mutant = numba.njit(_indexed_in_place), numba.njit(_a_copy_per_step)
    assert plain(a, 4) == mutant(a, 4)
    assert nrt_calls_on_loops(plain) == 0
    assert nrt_calls_on_loops(mutant) > 0
