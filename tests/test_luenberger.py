"""The poles of the Luenberger observer set beside an unknown input observer."""

from __future__ import annotations

import numpy as np
import pytest

import uio_teach as ut
from uio_teach.luenberger import luenberger_poles


def assert_same(actual, expected):
    """The requested poles are passed through (sorted), not computed: equal exactly."""
    np.testing.assert_array_equal(actual, expected)


def test_same_poles_when_they_fit():
    assert_same(luenberger_poles(ut.examples.pa9(), [-1, -2, -3]).real, [-3, -2, -1])


def test_too_few_poles_get_faster_real_ones():
    """Missile, g-inverse: two poles given, four needed; extras at 1.5 and 2 times the fastest."""
    missile = ut.examples.missile_autopilot()
    g = ut.design_ginverse(missile)
    given = g.poles()
    poles = luenberger_poles(missile, given)
    assert poles.size == 4
    # the g-inverse poles are eigenvalues, -105.6 to the 1e-6 their conditioning allows
    np.testing.assert_allclose(sorted(poles.real)[:2], [2 * -105.6, 1.5 * -105.6], rtol=1e-6)
    np.testing.assert_array_equal(np.sort_complex(poles)[2:], np.sort_complex(given))


def test_modes_no_gain_moves_are_taken_out():
    """Case study: (A, C) leaves 0.5 unobservable, so one 0.5 is taken out."""
    case = ut.examples.dt_case_study()
    assert np.allclose(np.sort(luenberger_poles(case, [0.2, 0.5, 0.5]).real), [0.2, 0.5])


def test_too_many_poles_lose_the_fastest():
    assert_same(luenberger_poles(ut.examples.pa9(), [-1, -2, -3, -9]).real, [-3, -2, -1])


def test_poles_repeated_beyond_the_outputs_stay_and_are_placed():
    pa9 = ut.examples.pa9()
    poles = luenberger_poles(pa9, [-2, -2, -2])
    assert poles.tolist() == [-2, -2, -2]
    F = ut.design_luenberger(pa9, poles=poles).F
    # a triple pole moves by about (eps ||F||)^(1/3) under round-off: the conditioning
    bound = 100 * (np.finfo(float).eps * np.linalg.norm(F, 2)) ** (1 / 3)
    assert np.abs(np.linalg.eigvals(F) + 2).max() <= bound


def test_a_plant_with_two_equal_modes_takes_a_triple_pole():
    # A has the eigenvalue -2 twice with two eigenvectors (not cyclic): no single output
    # combination w C observes it, a preliminary injection makes A - L0 C cyclic first
    plant = ut.worked.pa9.PA9.plant()
    w, V = np.linalg.eig(plant.A)
    assert np.linalg.matrix_rank(V[:, np.isclose(w, -2)]) == 2
    obs = ut.design_luenberger(plant, poles=[-1, -1, -1])
    bound = 100 * (np.finfo(float).eps * np.linalg.norm(obs.F, 2)) ** (1 / 3)
    assert np.abs(np.linalg.eigvals(obs.F) + 1).max() <= bound


DESIGNS = {
    "pa9": lambda: ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3]),
    "case-study": lambda: ut.design_pmo(ut.examples.dt_case_study(), method="lmi"),
    "missile": lambda: ut.design_pmo(ut.examples.missile_autopilot(), poles=[-100, -120]),
    "missile-ginverse": lambda: ut.design_ginverse(ut.examples.missile_autopilot()),
}


@pytest.mark.parametrize("name", sorted(DESIGNS))
def test_the_luenberger_observer_gets_every_one_of_these_poles(name):
    observer = DESIGNS[name]()
    plant = observer.plant
    target = luenberger_poles(plant, observer.poles())
    placed = ut.design_luenberger(plant, poles=target).poles()
    for p in target:
        assert np.min(np.abs(placed - p)) <= 1e-6 * max(1.0, abs(p)), (p, placed)
    assert placed.size == plant.n  # the unobservable modes of (A, C) stay as they are
