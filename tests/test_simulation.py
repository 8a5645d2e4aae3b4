"""simulate(): the defining property of an unknown input observer, exactness, and clear errors.

The reference solutions are computed here from the plant and observer matrices (a Python loop,
``scipy.linalg.expm``, ``scipy.integrate.solve_ivp``, ``control.forced_response``), never from
stored simulation outputs.
"""

from __future__ import annotations

import math
import warnings

import control as ct
import matplotlib.pyplot as plt
import numpy as np
import pytest
import scipy.linalg as sla
from scipy.integrate import solve_ivp
from tolerance import (
    assert_rounding_close,
    assert_same_run,
    eigenvector_condition,
    roundoff,
    size_of,
)

import uio_teach as ut
from uio_teach import examples, signals

X0_PA9 = np.array([1.0, -0.5, 2.0])
X0_CASE = np.array([1.0, -1.0, 2.0])
X0_MISSILE = np.asarray(examples.MISSILE_PUBLISHED.x0)


def _pa9_grid() -> np.ndarray:
    return np.linspace(0.0, 10.0, 2001)


def _missile_grid() -> np.ndarray:
    return np.linspace(0.0, 0.2, 2001)


def _case_grid() -> np.ndarray:
    return np.arange(40.0)


# (id, plant factory, observer factory, grid, initial state)
OBSERVERS = [
    ("pa9-uio", examples.pa9, lambda p: ut.design_uio(p, poles=[-1, -2, -3]), _pa9_grid, X0_PA9),
    ("pa9-pmo", examples.pa9, lambda p: ut.design_pmo(p, poles=[-2, -3, -4]), _pa9_grid, X0_PA9),
    ("pa9-ginverse", examples.pa9, ut.design_ginverse, _pa9_grid, X0_PA9),
    (
        "case-uio",
        examples.dt_case_study,
        lambda p: ut.design_uio(p, poles=[0.2]),
        _case_grid,
        X0_CASE,
    ),
    (
        "case-pmo-place",
        examples.dt_case_study,
        lambda p: ut.design_pmo(p, poles=[0.1]),
        _case_grid,
        X0_CASE,
    ),
    (
        "case-pmo-lmi",
        examples.dt_case_study,
        lambda p: ut.design_pmo(p, method="lmi"),
        _case_grid,
        X0_CASE,
    ),
    (
        "missile-uio",
        examples.missile_autopilot,
        lambda p: ut.design_uio(p, poles=[-80, -120]),
        _missile_grid,
        X0_MISSILE,
    ),
    (
        "missile-pmo",
        examples.missile_autopilot,
        lambda p: ut.design_pmo(p, poles=[-80, -120]),
        _missile_grid,
        X0_MISSILE,
    ),
    ("missile-ginverse", examples.missile_autopilot, ut.design_ginverse, _missile_grid, X0_MISSILE),
]
IDS = [case[0] for case in OBSERVERS]

LUENBERGER_POLES = {
    "PA9": [-1, -2, -3],
    "case study": [0.1, 0.2],  # (A, C) has an unobservable mode at 0.5
    "missile autopilot": [-100, -120, -140, -160],
}


def _unknown_inputs(plant: ut.Plant, t: np.ndarray) -> dict[str, dict]:
    """Unknown inputs (and measurement disturbances) of four kinds, sized for the plant."""
    q, r = plant.q, plant.nv
    amp = 50.0 if plant.name == "missile autopilot" else 2.0
    span = t[-1] - t[0]
    rng = np.random.default_rng(20141)

    def sines(k: int, base: float) -> list:
        return [signals.sinusoid(amp * (i + 1), base * (i + 1) / span) for i in range(k)]

    def steps(k: int) -> list:
        cuts = [t[0], t[0] + 0.3 * span, t[0] + 0.6 * span]
        return [
            signals.piecewise_constant(cuts, [amp, -amp * (i + 1), 0.5 * amp]) for i in range(k)
        ]

    def noise(k: int) -> np.ndarray:  # random levels held for about 1/40 of the run
        hold = max(1, t.size // 40)
        return np.repeat(rng.standard_normal((k, t.size // hold + 1)), hold, axis=1)[:, : t.size]

    variants = {
        "zero": {},
        "sinusoidal": {"d": sines(q, 20.0)},
        "piecewise constant": {"d": steps(q)},
        "random": {"d": amp * noise(q)},
    }
    if r:  # the measurement disturbance varies too
        variants["sinusoidal"]["v"] = signals.stack(*sines(r, 7.0))
        variants["piecewise constant"]["v"] = steps(r)
        variants["random"]["v"] = amp * noise(r)
    return variants


@pytest.mark.parametrize(("name", "make_plant", "make_observer", "grid", "x0"), OBSERVERS, ids=IDS)
def test_error_does_not_depend_on_the_unknown_input(name, make_plant, make_observer, grid, x0):
    plant = make_plant()
    obs = make_observer(plant)
    assert obs.decouples
    t = grid()
    runs = {
        kind: ut.simulate(plant, obs, t, initial_state=x0, **inputs)
        for kind, inputs in _unknown_inputs(plant, t).items()
    }
    base = runs.pop("zero")
    scale = np.abs(base.error).max()
    assert scale > 0.1  # the initial error is not trivial
    for kind, run in runs.items():
        # the unknown input really acted on the plant ...
        moved = np.abs(run.states - base.states).max()
        assert moved > 0.01 * np.abs(base.states).max(), (name, kind, moved)
        # ... and the estimation error did not notice
        assert_same_run(run.error, base.error, run, base, what=f"{name}, {kind}")


@pytest.mark.parametrize(
    "make_plant", [examples.pa9, examples.dt_case_study, examples.missile_autopilot]
)
def test_a_luenberger_observer_is_driven_by_the_unknown_input(make_plant):
    plant = make_plant()
    grid = {"PA9": _pa9_grid, "case study": _case_grid, "missile autopilot": _missile_grid}
    x0 = {"PA9": X0_PA9, "case study": X0_CASE, "missile autopilot": X0_MISSILE}[plant.name]
    t = grid[plant.name]()
    luenberger = ut.design_luenberger(plant, poles=LUENBERGER_POLES[plant.name])
    assert not luenberger.decouples
    uio = next(make_obs(plant) for _, mp, make_obs, _, _ in OBSERVERS if mp is make_plant)
    variants = _unknown_inputs(plant, t)
    for obs, decoupled in ((uio, True), (luenberger, False)):
        base = ut.simulate(plant, obs, t, initial_state=x0)
        scale = np.abs(base.error).max()
        for kind in ("sinusoidal", "piecewise constant", "random"):
            run = ut.simulate(plant, obs, t, initial_state=x0, **variants[kind])
            change = np.abs(run.error - base.error).max() / scale
            if decoupled:
                assert_same_run(run.error, base.error, run, base, what=f"{obs.family}, {kind}")
            else:
                # 5 % of the initial error: over 10^7 times what the UIO allows
                assert change > 0.05, (obs.family, kind, change)


@pytest.mark.parametrize(("name", "make_plant", "make_observer", "grid", "x0"), OBSERVERS, ids=IDS)
def test_error_decays_as_the_error_matrix_says(name, make_plant, make_observer, grid, x0):
    plant = make_plant()
    obs = make_observer(plant)
    t = grid()
    inputs = _unknown_inputs(plant, t)["sinusoidal"]
    run = ut.simulate(
        plant, obs, t, initial_state=x0, observer_state=np.ones(obs.plant.n), **inputs
    )
    e0 = run.error[:, 0]
    Ae = obs.error_matrix
    picks = np.unique(np.linspace(0, t.size - 1, 60).astype(int))
    if plant.is_discrete:
        expected = np.column_stack([np.linalg.matrix_power(Ae, int(k)) @ e0 for k in picks])
    else:
        expected = np.column_stack([sla.expm(Ae * (t[k] - t[0])) @ e0 for k in picks])
    scale = np.abs(e0).max()
    assert scale > 0.1
    # the reference's scaling and squaring adds ||F|| t steps to the run's samples
    steps = t.size + (0 if plant.is_discrete else np.linalg.norm(Ae, 1) * (t[-1] - t[0]))
    assert_rounding_close(
        run.error[:, picks],
        expected,
        size=size_of(run.states, run.estimates),
        terms=plant.n**2,
        steps=steps,
        gain=eigenvector_condition(Ae),
    )
    # and it does decay
    assert np.abs(run.error[:, -1]).max() < 1e-3 * scale


# exactness of the continuous-time solution ------------------------------------------------


def _joint_rhs(plant, obs, dfun, ufun=None):
    A_o, B_u, B_y, _, _ = obs.realization()
    n = plant.n

    def rhs(t, z):
        x, w = z[:n], z[n:]
        u = np.zeros(plant.m) if ufun is None else np.atleast_1d(ufun(t))
        y = plant.C @ x
        return np.concatenate(
            [plant.A @ x + plant.B @ u + plant.E @ dfun(t), A_o @ w + B_u @ u + B_y @ y]
        )

    return rhs


@pytest.mark.parametrize("family", ["PMO", "g-inverse"])
def test_missile_agrees_with_a_tight_ode_solver(family):
    plant = examples.missile_autopilot()
    obs = ut.design_ginverse(plant) if family == "g-inverse" else ut.design_pmo(plant, [-80, -120])
    t = np.linspace(0.0, 0.2, 20001)  # fine enough for the 100 rad/s input: FOH error ~ h^2
    d = examples.missile_inputs()
    run = ut.simulate(plant, obs, t, d=d, initial_state=X0_MISSILE)
    nw = obs.realization().A.shape[0]
    sol = solve_ivp(
        _joint_rhs(plant, obs, d),
        (t[0], t[-1]),
        np.concatenate([X0_MISSILE, np.zeros(nw)]),
        method="DOP853",
        rtol=1e-11,
        atol=1e-11,
        t_eval=t,
    )
    assert sol.success
    x, w = sol.y[: plant.n], sol.y[plant.n :]
    _, _, _, C_o, D_y = obs.realization()
    xhat = C_o @ w + D_y @ (plant.C @ x)

    def rel(a, b):
        return np.abs(a - b).max() / np.abs(b).max()

    assert rel(run.states, x) < 1e-7
    assert rel(run.observer_states, w) < 1e-7
    assert rel(run.estimates, xhat) < 1e-7
    assert rel(run.error, x - xhat) < 1e-7


@pytest.mark.slow
def test_pa9_with_known_input_agrees_with_a_tight_ode_solver():
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -3])
    t = np.linspace(0.0, 10.0, 40001)  # FOH error ~ (h w)^2: h = 2.5e-4
    u = signals.stack(signals.sinusoid(1.0, 2.0), signals.sinusoid(0.5, 0.7, offset=0.2))
    d = signals.sinusoid(2.0, 1.5)
    run = ut.simulate(plant, obs, t, u=u, d=d, initial_state=X0_PA9)
    sol = solve_ivp(
        _joint_rhs(plant, obs, lambda s: np.atleast_1d(d(s)), u),
        (t[0], t[-1]),
        np.concatenate([X0_PA9, np.zeros(3)]),
        method="Radau",
        rtol=1e-11,
        atol=1e-11,
        t_eval=t,
    )
    assert sol.success
    assert np.abs(run.states - sol.y[:3]).max() / np.abs(sol.y[:3]).max() < 1e-7
    assert np.abs(run.observer_states - sol.y[3:]).max() / np.abs(sol.y[3:]).max() < 1e-7


def _forced_response(plant, obs, t, u, d, v, x0):
    """The same joint system built here from the matrices, solved by python-control."""
    A_o, B_u, B_y, C_o, D_y = obs.realization()
    n, nw = plant.n, A_o.shape[0]
    A = np.block([[plant.A, np.zeros((n, nw))], [B_y @ plant.C, A_o]])
    B = np.block(
        [[plant.B, plant.E, np.zeros((n, plant.nv))], [B_u, np.zeros((nw, plant.q)), B_y @ plant.D]]
    )
    sys = ct.ss(A, B, np.eye(n + nw), 0, dt=0 if plant.dt is None else plant.dt)
    U = np.vstack([u, d, v])
    res = ct.forced_response(sys, t, U, X0=np.concatenate([x0, np.zeros(nw)]))
    return res.states[:n], res.states[n:]


@pytest.mark.parametrize(("name", "make_plant", "make_observer", "grid", "x0"), OBSERVERS, ids=IDS)
def test_agrees_with_control_forced_response(name, make_plant, make_observer, grid, x0):
    plant = make_plant()
    obs = make_observer(plant)
    t = grid()
    rng = np.random.default_rng(7)
    u = rng.standard_normal((plant.m, t.size))
    inputs = _unknown_inputs(plant, t)["random"]
    d = inputs["d"]
    v = inputs.get("v", np.zeros((plant.nv, t.size)))
    run = ut.simulate(
        plant, obs, t, u=u if plant.m else None, d=d, v=v if plant.nv else None, initial_state=x0
    )
    x, w = _forced_response(plant, obs, t, u, d, v, x0)
    # two exact solutions of one linear system: rounding of the joint (n + n_w)-state recursion
    nj = plant.n + w.shape[0]
    gain = eigenvector_condition(obs.error_matrix) * eigenvector_condition(plant.A)
    for ours, theirs in ((run.states, x), (run.observer_states, w)):
        assert_rounding_close(
            ours, theirs, size=size_of(x, w, u, d), terms=nj**2, steps=t.size, gain=gain
        )


def test_discrete_simulation_is_the_plant_recursion():
    plant = examples.dt_case_study()
    obs = ut.design_pmo(plant, method="lmi")
    t = np.arange(30.0)
    rng = np.random.default_rng(3)
    d, v = rng.standard_normal((1, 30)), rng.standard_normal((1, 30))
    w0 = np.array([0.3, -0.2, 0.1])
    run = ut.simulate(plant, obs, t, d=d, v=v, initial_state=X0_CASE, observer_state=w0)
    A_o, _, B_y, C_o, D_y = obs.realization()
    x, w = X0_CASE.copy(), w0.copy()
    for k in range(30):
        y = plant.C @ x + plant.D @ v[:, k]
        # k steps of 3-term products, summed in another order than the simulator's
        size = size_of(x, w, y, d[:, : k + 1], v[:, : k + 1])
        gain = eigenvector_condition(plant.A) * eigenvector_condition(A_o)
        tol = dict(size=size, terms=9, steps=k + 1, gain=gain)
        assert_rounding_close(run.states[:, k], x, **tol)
        assert_rounding_close(run.outputs[:, k], y, **tol)
        assert_rounding_close(run.estimates[:, k], C_o @ w + D_y @ y, **tol)
        x, w = plant.A @ x + plant.E @ d[:, k], A_o @ w + B_y @ y


def test_exact_for_inputs_linear_between_samples():
    """A ramp and a triangle are linear between samples: a coarse grid loses nothing."""
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -3])
    fine = np.linspace(0.0, 8.0, 8001)
    coarse = fine[::400]  # 21 points, step 0.4

    def triangle(s):
        return 1.0 - np.abs(np.mod(s, 1.6) - 0.8) / 0.4  # kinks at multiples of 0.4

    def ramp(s):
        return np.vstack([0.25 * s, -0.5 * s])

    a = ut.simulate(plant, obs, fine, u=ramp, d=triangle, initial_state=X0_PA9)
    b = ut.simulate(plant, obs, coarse, u=ramp, d=triangle, initial_state=X0_PA9)
    # equal up to the rounding of the fine run's 8001 steps
    assert_same_run(b.states, a.states[:, ::400], a, b)
    assert_same_run(b.estimates, a.estimates[:, ::400], a, b)


def test_non_uniform_grid_uses_the_same_exact_solution():
    plant = examples.missile_autopilot()
    obs = ut.design_ginverse(plant)
    uniform = np.linspace(0.0, 0.05, 501)
    # every other point dropped at random: a non-uniform grid on the same time points
    keep = np.sort(np.concatenate([[0, 500], np.random.default_rng(1).choice(499, 250, False) + 1]))
    uneven = uniform[keep]

    def ramp(s):
        return np.vstack([20 * s, -30 * s + 1])  # linear: exact on any grid

    a = ut.simulate(plant, obs, uniform, d=ramp, initial_state=X0_MISSILE)
    b = ut.simulate(plant, obs, uneven, d=ramp, initial_state=X0_MISSILE)
    assert_same_run(b.states, a.states[:, keep], a, b)
    assert_same_run(b.estimates, a.estimates[:, keep], a, b)


# the result object ----------------------------------------------------------------------------


def test_response_fields_are_consistent():
    plant = examples.dt_case_study()
    obs = ut.design_pmo(plant, method="lmi")
    t = np.arange(20.0)
    run = ut.simulate(plant, obs, t, d=np.sin(t), v=np.cos(t), initial_state=X0_CASE, noise=0.1)
    assert run.time.shape == (20,)
    assert run.states.shape == run.estimates.shape == run.error.shape == (3, 20)
    assert run.outputs.shape == run.residual.shape == (2, 20)
    assert run.observer_states.shape == (3, 20)
    np.testing.assert_array_equal(run.error, run.states - run.estimates)
    # one product with n (and nv) terms, summed in any order
    size = size_of(run.outputs, run.states, run.estimates, run.inputs.v, run.inputs.noise)
    size *= size_of(plant.C, plant.D)
    assert_rounding_close(
        run.residual, run.outputs - plant.C @ run.estimates, size=size, terms=plant.n
    )
    assert_rounding_close(
        run.outputs,
        plant.C @ run.states + plant.D @ run.inputs.v + run.inputs.noise,
        size=size,
        terms=plant.n + plant.nv + 1,
    )
    assert run.inputs.u.shape == (0, 20)
    np.testing.assert_array_equal(run.inputs.d, np.sin(t)[None])
    np.testing.assert_array_equal(run.inputs.v, np.cos(t)[None])
    assert run.plant is plant and run.observer is obs
    text = repr(run)
    assert "PMO" in text and "case study" in text and "20 samples" in text
    # a discrete run is read in steps, not seconds
    assert "steps k = 0 ... 19" in text and "t = " not in text


def test_observer_state_sets_the_first_estimate():
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -3])
    w0 = np.array([0.5, -1.0, 2.0])
    run = ut.simulate(plant, obs, np.linspace(0, 1, 11), initial_state=X0_PA9, observer_state=w0)
    _, _, _, C_o, D_y = obs.realization()
    np.testing.assert_allclose(run.estimates[:, 0], C_o @ w0 + D_y @ (plant.C @ X0_PA9))
    np.testing.assert_array_equal(run.observer_states[:, 0], w0)
    default = ut.simulate(plant, obs, np.linspace(0, 1, 11), initial_state=X0_PA9)
    np.testing.assert_array_equal(default.observer_states[:, 0], 0.0)


def test_signal_forms_are_equivalent():
    plant = examples.missile_autopilot()
    obs = ut.design_ginverse(plant)
    t = np.linspace(0.0, 0.1, 501)
    v1 = signals.damped_sinusoid(10, 2, 10, "cos")
    v2 = signals.damped_sinusoid(50, 5, 100, "sin")
    forms = [
        examples.missile_inputs(),  # a stack
        [v1, v2],  # a list of scalar callables
        (v1, v2),
        lambda s: np.vstack([v1(s), v2(s)]),  # any vectorized function
        np.vstack([v1(t), v2(t)]),  # samples
        np.vstack([v1(t), v2(t)]).tolist(),
    ]
    runs = [ut.simulate(plant, obs, t, d=f, initial_state=X0_MISSILE) for f in forms]
    for run in runs[1:]:
        np.testing.assert_array_equal(run.states, runs[0].states)
    # one channel: 1-D samples, (1, N) samples, scalar function returning (N,)
    pa9 = examples.pa9()
    uio = ut.design_uio(pa9, poles=[-1, -2, -3])
    s = np.linspace(0, 2, 101)
    d_forms = [signals.sinusoid(), np.sin(s), np.sin(s)[None], np.sin, [signals.sinusoid()]]
    runs = [ut.simulate(pa9, uio, s, d=f) for f in d_forms]
    for run in runs[1:]:  # the same samples: equal to rounding (a vectorized sin, a scalar one)
        assert_same_run(run.states, runs[0].states, run, runs[0])
    assert np.abs(runs[0].states).max() > 0.1


def test_discrete_plant_with_unspecified_period_takes_any_uniform_spacing():
    case = examples.dt_case_study()
    steps = ut.Plant(case.A, case.C, E=case.E, D=case.D, dt=True, name="steps")
    obs_case = ut.design_pmo(case, method="lmi")
    obs_steps = ut.design_pmo(steps, L=obs_case.L)
    d = np.cos(np.arange(15.0))
    a = ut.simulate(case, obs_case, np.arange(15.0), d=d, initial_state=X0_CASE)
    b = ut.simulate(steps, obs_steps, 0.25 * np.arange(15.0) + 3, d=d, initial_state=X0_CASE)
    assert_same_run(b.estimates, a.estimates, a, b)  # the same recursion, another time axis
    fig = b.plot()
    assert {ax.get_xlabel() for ax in fig.axes} - {""} == {"step k"}
    fig_a = a.plot()  # a sampling period of 1 counts steps too
    assert {ax.get_xlabel() for ax in fig_a.axes} - {""} == {"step k"}
    plt.close("all")


def test_plot_draws_states_error_and_residual():
    plant = examples.missile_autopilot()
    run = ut.simulate(
        plant,
        ut.design_ginverse(plant),
        np.linspace(0, 0.1, 201),
        d=examples.missile_inputs(),
        initial_state=X0_MISSILE,
    )
    fig = run.plot()
    assert len(fig.axes) == plant.n + 2
    labels = sorted(ax.get_ylabel() for ax in fig.axes)
    assert labels[:4] == [f"$x_{{{i}}}$ (model units)" for i in range(1, 5)]
    assert any(label.startswith("error") for label in labels)
    assert any(label.startswith("residual") for label in labels)
    assert {ax.get_xlabel() for ax in fig.axes} - {""} == {"time (s)"}
    # each state panel shows the state and its estimate
    state_ax = next(ax for ax in fig.axes if ax.get_ylabel() == "$x_{3}$ (model units)")
    lines = state_ax.get_lines()
    np.testing.assert_array_equal(lines[0].get_ydata(), run.states[2])
    np.testing.assert_array_equal(lines[1].get_ydata(), run.estimates[2])
    # into given axes
    fig2, axes = plt.subplots(plant.n + 2, 1)
    assert run.plot(axes=axes) is fig2
    assert axes[-1].get_ylabel().startswith("residual")
    with pytest.raises(ValueError, match="axes must hold 6 axes"):
        run.plot(axes=axes[:3])
    plt.close("all")


# noise ----------------------------------------------------------------------------------------


def test_noise_is_reproducible_from_the_seed():
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -3])
    t = np.linspace(0, 20, 20001)
    a = ut.simulate(plant, obs, t, noise=[0.1, 0.5], seed=42)
    b = ut.simulate(plant, obs, t, noise=[0.1, 0.5], seed=42)
    c = ut.simulate(plant, obs, t, noise=[0.1, 0.5], seed=43)
    np.testing.assert_array_equal(a.outputs, b.outputs)
    np.testing.assert_array_equal(a.estimates, b.estimates)
    assert np.abs(a.outputs - c.outputs).max() > 0.1
    np.testing.assert_allclose(a.inputs.noise.std(axis=1), [0.1, 0.5], rtol=0.03)
    # measurement noise does not touch the plant state, only what the observer sees
    quiet = ut.simulate(plant, obs, t)
    assert_same_run(a.states, quiet.states, a, quiet)
    assert_rounding_close(
        a.outputs - plant.C @ a.states,
        a.inputs.noise,
        size=size_of(a.outputs) + size_of(plant.C) * size_of(a.states),
        terms=plant.n + 1,
    )
    assert np.abs(a.error).max() > 0.01
    # a scalar is one standard deviation for every output; a Generator works as the seed
    d = ut.simulate(plant, obs, t, noise=0.2, seed=np.random.default_rng(5))
    np.testing.assert_allclose(d.inputs.noise.std(axis=1), [0.2, 0.2], rtol=0.03)


# clear errors -----------------------------------------------------------------------------------


@pytest.fixture
def pa9_setup():
    plant = examples.pa9()
    return plant, ut.design_uio(plant, poles=[-1, -2, -3]), np.linspace(0, 1, 101)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"d": np.zeros((2, 101))}, r"d must have shape \(1, 101\).*got \(2, 101\)"),
        ({"d": np.zeros(100)}, r"d must have shape \(1, 101\).*got \(1, 100\)"),
        ({"d": np.zeros((1, 101, 1))}, r"d must have shape \(1, 101\).*got \(1, 101, 1\)"),
        ({"d": 1.0}, r"d must have shape \(1, 101\).*got \(\)"),
        ({"u": np.zeros((1, 101))}, r"u must have shape \(2, 101\).*got \(1, 101\)"),
        ({"u": np.zeros(101)}, r"u must have shape \(2, 101\)"),
        (
            {"d": lambda t: np.zeros((2, t.size))},
            r"d\(t\) must return .*\(1, 101\).*got shape \(2, 101\)",
        ),
        ({"d": lambda t: 1.0}, r"d\(t\) must return.*got shape \(\).*c \+ 0 \* t"),
        ({"u": signals.sinusoid()}, r"u\(t\) must return .*\(2, 101\).*got shape \(101,\)"),
        ({"u": [signals.sinusoid()]}, r"u is a list of 1 signals, expected 2"),
        ({"u": [signals.sinusoid(), lambda t: np.ones((2, t.size))]}, r"u\[1\]\(t\) must return"),
        ({"d": math.sin}, r"calling d with the array of 101 time points failed.*vectorized"),
        ({"v": np.zeros(101)}, r"v was given but the plant has no measurement disturbance"),
        ({"d": np.where(np.arange(101) == 7, np.nan, 0.0)}, r"d has a non-finite value nan.*7"),
        ({"d": lambda t: np.where(t > 0.5, np.inf, 0.0)}, r"d has a non-finite value inf"),
        ({"d": np.zeros(101) + 1j}, r"d must be real"),
        ({"initial_state": [1.0, 2.0]}, r"initial_state must have length 3.*got shape \(2,\)"),
        ({"initial_state": np.ones((3, 3))}, r"initial_state must have length 3"),
        ({"initial_state": [1.0, np.nan, 0.0]}, r"initial_state must be finite"),
        ({"observer_state": np.ones(4)}, r"observer_state must have length 3"),
        ({"noise": [0.1, 0.2, 0.3]}, r"noise must be .* \(length 2\), got shape \(3,\)"),
        ({"noise": -0.1}, r"noise standard deviations must be finite and >= 0"),
    ],
)
def test_bad_arguments_name_the_argument(pa9_setup, kwargs, pattern):
    plant, obs, t = pa9_setup
    with pytest.raises(ValueError, match=pattern):
        ut.simulate(plant, obs, t, **kwargs)


@pytest.mark.parametrize(
    ("timepts", "pattern"),
    [
        ([0.0, 1.0, 1.0, 2.0], r"timepts must be strictly increasing: timepts\[1\] = 1"),
        ([0.0, 2.0, 1.0], r"timepts must be strictly increasing"),
        ([0.0, np.inf], r"timepts must be finite"),
        ([[0.0, 1.0]], r"timepts must be a 1-D array"),
        ([0.0], r"timepts must hold at least 2 time points"),
        ("abc", r"timepts must be a 1-D array"),
    ],
)
def test_bad_time_points(pa9_setup, timepts, pattern):
    plant, obs, _ = pa9_setup
    with pytest.raises(ValueError, match=pattern):
        ut.simulate(plant, obs, timepts)


def test_discrete_plant_needs_its_sampling_grid():
    plant = examples.dt_case_study()
    obs = ut.design_pmo(plant, method="lmi")
    with pytest.raises(ValueError, match=r"timepts .* spacing must equal dt = 1, got 0.5"):
        ut.simulate(plant, obs, np.arange(0, 10, 0.5))
    with pytest.raises(ValueError, match=r"timepts .*sampling grid.*non-uniform"):
        ut.simulate(plant, obs, [0.0, 1.0, 2.0, 4.0])
    # on the grid, any start is fine
    ut.simulate(plant, obs, np.arange(10.0) + 100.0)


def test_plant_and_observer_must_match():
    pa9 = examples.pa9()
    missile = examples.missile_autopilot()
    obs = ut.design_ginverse(missile)
    t = np.linspace(0, 1, 11)
    with pytest.raises(ValueError, match="observer was designed for a plant with n = 4"):
        ut.simulate(pa9, obs, t)
    with pytest.raises(ValueError, match="plant must be a uio_teach.Plant"):
        ut.simulate(pa9.as_statespace(), obs, t)
    with pytest.raises(ValueError, match="observer must be a uio_teach observer"):
        ut.simulate(missile, "observer", t)
    case = examples.dt_case_study()
    continuous = ut.Plant(case.A - np.eye(3), case.C, E=case.E, D=case.D)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        obs_case = ut.design_pmo(case, method="lmi")
    with pytest.raises(ValueError, match="both continuous-time or both discrete-time"):
        ut.simulate(continuous, obs_case, t)


def test_a_different_true_plant_shows_model_error():
    """The true plant may differ from the design model: the decoupling is then lost."""
    model = examples.pa9()
    obs = ut.design_uio(model, poles=[-1, -2, -3])
    true = ut.Plant(model.A * 1.2, model.C, B=model.B, E=model.E, name="perturbed")
    t = np.linspace(0, 10, 1001)
    d = signals.sinusoid(2.0, 1.0)
    exact = ut.simulate(model, obs, t, d=d)
    wrong = ut.simulate(true, obs, t, d=d)
    assert_same_run(exact.error, 0, exact)
    assert np.abs(wrong.error).max() > 1e-2


# --- arguments and overflow -----------------------------------------------------------------


@pytest.mark.parametrize("seed", [-1, 1.5, "x", True, [1, 2]])
def test_seed_must_be_a_non_negative_integer(seed):
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -3])
    with pytest.raises(ValueError, match="^seed must be None, a non-negative integer"):
        ut.simulate(plant, obs, np.linspace(0, 1, 11), noise=0.1, seed=seed)


def test_valid_seeds_reproduce_the_noise():
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -3])
    t = np.linspace(0, 1, 11)
    a = ut.simulate(plant, obs, t, noise=0.1, seed=np.int64(3)).outputs
    b = ut.simulate(plant, obs, t, noise=0.1, seed=3).outputs
    c = ut.simulate(plant, obs, t, noise=0.1, seed=np.random.default_rng(3)).outputs
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, c)


@pytest.mark.parametrize("noise", ["0.1", b"0.1", True, 0.1j, [np.nan, 0.1], -0.1])
def test_noise_must_be_a_finite_non_negative_number(noise):
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -3])
    with pytest.raises(ValueError, match="^noise"):
        ut.simulate(plant, obs, np.linspace(0, 1, 11), noise=noise)


def test_stiff_but_stable_observer_pole_is_simulated():
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -1e4])
    t = np.linspace(0, 2, 201)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run = ut.simulate(plant, obs, t, initial_state=[1, 0, 0], d=signals.step(1.0))
    assert np.all(np.isfinite(run.error))
    # the error obeys e' = F e: compare with the matrix exponential
    e0 = run.error[:, 0]
    assert_rounding_close(
        run.error[:, -1],
        sla.expm(obs.F * 2.0) @ e0,
        size=size_of(run.states, run.estimates),
        terms=plant.n**2,
        steps=t.size + np.linalg.norm(obs.F, 1) * 2.0,
        gain=eigenvector_condition(obs.F),
    )


@pytest.mark.parametrize(("pole", "t_end"), [(100.0, 10.0), (1e4, 1.0), (100.0, 1e4)])
def test_overflow_names_the_unstable_pole_and_the_time(pole, t_end):
    plant = examples.pa9()
    with pytest.warns(ut.UnstableObserverWarning):
        obs = ut.design_uio(plant, poles=[-1, -2, pole])
    t = np.linspace(0, t_end, 1001)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no raw overflow warnings
        with pytest.raises(ut.simulation.SimulationOverflowError) as info:
            ut.simulate(plant, obs, t, initial_state=[1, 0, 0])
    err = info.value
    assert isinstance(err, OverflowError)
    assert f"{ut._display.format_complex(pole)} (observer)" in str(err)
    assert np.any(np.isclose(err.poles.real, pole))
    # the response leaves the float range (1e300) after about ln(1e300) / pole time units
    expected = math.log(1e300) / pole
    assert err.time >= min(expected, t[1]) - roundoff(t[-1])  # a time of the grid, t_end large
    assert err.time <= max(expected + 2 * (t[1] - t[0]), t[1])
    assert f"t = {err.time:g}" in str(err)


def test_unstable_plant_overflow_names_the_plant_pole():
    plant = ut.Plant([[50.0]], [[1.0]])
    obs = ut.design_luenberger(plant, poles=[-1.0])
    with pytest.raises(ut.simulation.SimulationOverflowError, match=r"50 \(plant\)"):
        ut.simulate(plant, obs, np.linspace(0, 20, 2001), initial_state=[1.0])


def test_overflow_names_a_pole_of_plant_and_observer_once_for_each():
    """An observer without gain keeps the plant's unstable pole: the joint system has it twice,
    once the plant's and once the observer's, and the message says so."""
    plant = ut.Plant([[50.0]], [[1.0]])
    with pytest.warns(ut.UnstableObserverWarning):
        obs = ut.design_luenberger(plant, L=[[0.0]])
    with pytest.raises(ut.simulation.SimulationOverflowError) as info:
        ut.simulate(plant, obs, np.linspace(0, 100, 101), initial_state=[1.0])
    assert "50 (plant), 50 (observer)" in str(info.value)
