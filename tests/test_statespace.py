"""The plant and the observers as python-control systems, wired together by signal names.

``plant.as_statespace()`` has inputs ``[u; d; v]`` and outputs ``y``; an observer's
``as_statespace()`` has inputs ``[u; y]`` and outputs ``xhat``. Interconnected by name
and simulated by python-control, they must give the estimate of :func:`uio_teach.simulate`;
an observer whose ``u`` and ``y`` columns were swapped would not.
"""

from __future__ import annotations

import control as ct
import numpy as np
import pytest
from tolerance import assert_rounding_close, size_of

import uio_teach as ut
from uio_teach.worked.case_study import CASE_STUDY
from uio_teach.worked.missile import MISSILE
from uio_teach.worked.pa9 import PA9


def _interconnect(plant: ut.Plant, observer) -> ct.StateSpace:
    """Plant and observer joined on ``y`` (and ``u``): inputs ``[u; d; v]``, outputs ``xhat``."""
    psys, osys = plant.as_statespace(), observer.as_statespace()
    assert psys.output_labels == [f"y[{i}]" for i in range(plant.p)]
    assert osys.input_labels[: plant.m] == [f"u[{i}]" for i in range(plant.m)]
    return ct.interconnect(
        [psys, osys],
        inplist=psys.input_labels,
        outlist=osys.output_labels,
        name="plant and observer",
    )


def _runs():
    case = ut.design_pmo(CASE_STUDY.plant(), method="lmi")
    yield "pa9-uio", PA9, ut.design_uio(PA9.plant(), poles=PA9.poles), {"d": PA9.d_sine}
    yield "pa9-luenberger", PA9, ut.design_luenberger(PA9.plant(), poles=PA9.poles), {}
    yield "case-study-pmo", CASE_STUDY, case, {}
    yield "missile-pmo", MISSILE, ut.design_pmo(MISSILE.plant(), poles=MISSILE.poles), {}


RUNS = {name: (exp, obs, kw) for name, exp, obs, kw in _runs()}


@pytest.mark.parametrize("name", sorted(RUNS))
def test_interconnected_plant_and_observer_give_the_simulated_estimate(name):
    experiment, observer, changes = RUNS[name]
    plant = experiment.plant()
    t = experiment.grid(samples=401) if not plant.is_discrete else experiment.timepts
    resp = experiment.simulate(observer, timepts=t, observer_state=None, **changes)
    loop = _interconnect(plant, observer)
    # python-control's inputs [u; d; v] are the ones simulate applied
    U = np.vstack([resp.inputs.u, resp.inputs.d, resp.inputs.v])
    assert U.shape == (loop.ninputs, t.size)
    x0 = np.concatenate([experiment.initial_state, np.zeros(loop.nstates - plant.n)])
    out = ct.forced_response(loop, timepts=t, inputs=U, initial_state=x0)
    scale = max(1.0, float(np.abs(resp.estimates).max()))
    np.testing.assert_allclose(out.outputs, resp.estimates, atol=1e-7 * scale)
    # the signals a mix-up would confuse differ here: u and y are not the same
    assert plant.m == 0 or not np.allclose(resp.inputs.u, resp.outputs[: plant.m])


def test_an_observer_fed_u_for_y_gives_another_estimate():
    """The check above can fail: with the u and y blocks swapped, the estimate changes."""
    plant = PA9.plant()
    observer = ut.design_uio(plant, poles=PA9.poles)
    osys = observer.as_statespace()
    m = plant.m
    swapped = ct.ss(
        osys.A,
        np.hstack([osys.B[:, m:], osys.B[:, :m]]),
        osys.C,
        np.hstack([osys.D[:, m:], osys.D[:, :m]]),
        inputs=osys.input_labels,
        outputs=osys.output_labels,
        name="swapped",
    )
    t = PA9.grid(samples=401)
    resp = PA9.simulate(observer, timepts=t)
    loop = ct.interconnect(
        [plant.as_statespace(), swapped],
        inplist=plant.as_statespace().input_labels,
        outlist=swapped.output_labels,
    )
    U = np.vstack([resp.inputs.u, resp.inputs.d])
    x0 = np.concatenate([PA9.initial_state, np.zeros(loop.nstates - plant.n)])
    out = ct.forced_response(loop, timepts=t, inputs=U, initial_state=x0)
    assert np.abs(out.outputs - resp.estimates).max() > 1e-2


@pytest.mark.parametrize("family", ["uio", "luenberger"])
def test_closed_loop_with_python_control(family):
    """At an equilibrium of the plant with a constant ``d``, the UIO's steady estimate is the
    plant's state; the Luenberger observer's is not (it does not decouple ``d``)."""
    plant = PA9.plant()
    design = ut.design_uio if family == "uio" else ut.design_luenberger
    observer = design(plant, poles=PA9.poles)
    u0, d0 = np.array([1.0, -0.5]), np.array([0.8])
    x_eq = -np.linalg.solve(plant.A, plant.B @ u0 + plant.E @ d0)
    y_eq = plant.C @ x_eq
    # the observer alone: its DC gain maps the constant [u; y] to its steady estimate
    xhat = ct.dcgain(observer.as_statespace()) @ np.concatenate([u0, y_eq])
    # the loop: from [u; d] to xhat through the plant
    loop = _interconnect(plant, observer)
    xhat_loop = ct.dcgain(loop) @ np.concatenate([u0, d0])
    # DC gains: solves with the loop's and the observer's matrices, their conditions the gain
    gain = np.linalg.cond(loop.A) * np.linalg.cond(observer.as_statespace().A)
    tol = dict(size=size_of(x_eq, xhat), terms=loop.A.shape[0] ** 2, gain=gain)
    assert_rounding_close(xhat_loop, xhat, **tol)
    if family == "uio":
        assert_rounding_close(xhat, x_eq, **tol)
    else:
        assert np.abs(xhat - x_eq).max() > 1e-3
    # without d both observers estimate the equilibrium exactly
    x_free = -np.linalg.solve(plant.A, plant.B @ u0)
    assert_rounding_close(ct.dcgain(loop) @ np.concatenate([u0, [0.0]]), x_free, **tol)
