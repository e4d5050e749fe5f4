"""The step loop: the one place that runs steps, for every way of refining.

:func:`walk` takes a :class:`~hybridsub._input.gate.RefineInput` and yields one :class:`Step`
per level: the level and its plan, the faces of the next level and the next level itself. It
carries the optional face-varying (UV) channel beside the geometry: each step plans the
geometry with seams as forced splits, then the UV index mesh with the geometry's split edges
as forced splits, so both make the same decisions and emit aligned faces. What a step yields
is turned into matrices (:mod:`.refinement`) or applied to data directly (:mod:`.fastpath`).

>>> from hybridsub._input.gate import open_gate
>>> [len(s.faces) for s in walk(open_gate([[0, 1, 2], [0, 2, 3]], levels=2))]
[10, 38]
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from typing import NamedTuple

import numpy as np

from .._input.gate import RefineInput
from .._rules import step_rules as R
from .._topology import Level, StepPlan, child_level, plan_step
from .._topology.uv import new_uv_corners
from .bar import level_bar, tick
from .budget import Budget


#: What ``walk(..., data_first=...)`` calls with each step's level and plan.
DataFirst = Callable[[Level, StepPlan], None]
EMPTY_WEIGHTS = np.empty((4, 0), np.float64)


class UVStep(NamedTuple):
    """The UV index mesh's part of a step."""

    level: Level  # UV index mesh of level k, and its plan
    plan: StepPlan
    faces: np.ndarray  # UV faces of level k + 1, aligned with the geometry's
    child: Level  # UV index mesh of level k + 1


class Step(NamedTuple):
    """One step of :func:`walk`: level k → k + 1."""

    step: int  # 1-based
    level: Level  # level k, and its plan
    plan: StepPlan
    faces: np.ndarray  # faces of level k + 1
    child: Level | None  # level k + 1 (None for the last step unless asked for)
    offsets: np.ndarray | None  # (m + 1,) child offsets of the faces of level k (None: last step, no topology)
    uv: UVStep | None  # with face-varying data


def walk(inp: RefineInput, budget: Budget | None = None, topology_last: bool = True,
         progress: bool | None = False, data_first: DataFirst | None = None) -> Iterator[Step]:
    """Run ``inp.levels`` steps; yield a :class:`Step` for each (none without faces).

    The next level's twins and tags are built for the last step only if ``topology_last``
    (always with face-varying data). ``budget`` may refuse before the first step allocates.
    ``progress``: a tqdm bar ticks after each step has been used (see :func:`.bar.level_bar`).
    ``data_first(level, plan)``, if given, is called before each step's faces are emitted (to
    refine the caller's data); then, on a last step without topology, the plan's vertex
    weights and the level's tags are dropped, so the new faces are not allocated beside them
    (the step yields the plan without ``coefficients`` and the level without ``hsharp``).
    """
    if inp.levels == 0 or inp.n_faces == 0:
        return
    with level_bar(inp.levels, progress, inp.scheme) as bar:
        for s in _steps(inp, budget, topology_last, data_first):
            yield s
            tick(bar, len(s.faces))
            del s  # nor here: the last step's plan and offsets are dropped before the next one's


def _steps(inp: RefineInput, budget: Budget | None, topology_last: bool,
           data_first: DataFirst | None) -> Iterator[Step]:
    level = inp.level
    corner = inp.corner if inp.corner_sharpness is None else inp.corner_sharpness  # semi-sharp: decays
    uvl = uv_fixed = None
    if inp.uv is not None:
        uvl, uv_fixed = inp.uv.level, inp.uv.corner
    for step in range(1, inp.levels + 1):
        # With UVs, seams are split (the UV mesh is cut exactly along them), and the UV mesh
        # splits every edge the geometry splits, so both emit aligned faces.
        seams = None if uvl is None else (uvl.twin < 0) & (level.twin >= 0)
        plan = plan_step(level, corner, inp.scheme, step, inp.loop_weights, force_split=seams)
        uv_plan = None
        if uvl is not None:
            uv_plan = plan_step(uvl, uv_fixed, inp.scheme, step, inp.loop_weights,
                                force_split=plan.hkind == R.EDGE_SPLIT)
            if not np.array_equal(uv_plan.hkind, plan.hkind):
                raise AssertionError("UV index mesh and geometry disagree on split edges")  # pragma: no cover
        if budget is not None:  # before this step allocates anything large
            budget.check(step, level, plan, also=None if uvl is None else (uvl, uv_plan))
        want = topology_last or step < inp.levels or uvl is not None
        if data_first is not None:
            data_first(level, plan)
            if not want:
                plan = dataclasses.replace(plan, coefficients=EMPTY_WEIGHTS)
                level = Level(level.faces, level.n_vertices, level.twin, None, level.face_sharp)
        faces, child, offsets = child_level(level, plan, want_topology=want)
        uv = None
        if uvl is not None:
            uv_faces, uv_child, _ = child_level(uvl, uv_plan)
            uv = UVStep(uvl, uv_plan, uv_faces, uv_child)
            if inp.uv.mode == "boundaries":
                added = new_uv_corners(uv.level, uv_plan, len(uv_fixed))
            else:
                added = np.zeros(uv_plan.n_new - len(uv_fixed), dtype=bool)
            uv_fixed = np.concatenate([uv_fixed, added])
            uvl = uv_child
        yield Step(step, level, plan, faces, child, offsets, uv)
        corner = next_corners(corner, plan.n_new)
        level = child
        del plan, uv_plan, faces, child, offsets, uv  # not held while the next step is planned


def next_corners(corner: np.ndarray, n_next: int) -> np.ndarray:
    """The corners of the next level (``n_next`` vertices): a mask carried as it is, or vertex
    sharpness (float64) decayed by one (``inf`` stays; new points are never corners).

    >>> next_corners(np.array([0.5, 2.5, np.inf]), 4).tolist()
    [0.0, 1.5, inf, 0.0]
    """
    if corner.dtype == np.float64:
        return np.concatenate([R.child_sharpness(corner), np.zeros(n_next - len(corner))])
    return np.concatenate([corner, np.zeros(n_next - len(corner), dtype=bool)])
