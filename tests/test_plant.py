"""Plant construction: shapes, finiteness, dt, immutability, python-control round trips."""

import control as ct
import numpy as np
import pytest

import uio_teach as ut

A2 = [[0.0, 1.0], [-2.0, -3.0]]


def test_dimensions_and_defaults():
    plant = ut.Plant(A2, [[1, 0]], E=[0, 1])
    assert (plant.n, plant.m, plant.q, plant.p, plant.nv) == (2, 0, 1, 1, 0)
    assert plant.B.shape == (2, 0) and plant.D.shape == (1, 0)
    assert not plant.is_discrete


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(A=[[1, 2, 3], [4, 5, 6]], C=[[1, 0, 0]]), r"A has shape \(2, 3\), expected a square"),
        (dict(A=A2, C=[[1, 0, 0]]), r"C has shape \(1, 3\), expected \(\?, 2\)"),
        (dict(A=A2, C=[[1, 0]], B=[[1], [2], [3]]), r"B has shape \(3, 1\), expected \(2, \?\)"),
        (dict(A=A2, C=[[1, 0]], E=np.ones((3, 2))), r"E has shape \(3, 2\), expected \(2, \?\)"),
        (dict(A=A2, C=[[1, 0]], D=np.ones((2, 1))), r"D has shape \(2, 1\), expected \(1, \?\)"),
    ],
)
def test_wrong_shapes_name_the_matrix(kwargs, message):
    A, C = kwargs.pop("A"), kwargs.pop("C")
    with pytest.raises(ValueError, match=message):
        ut.Plant(A, C, **kwargs)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("where", ["A", "C", "E"])
def test_non_finite_entries_are_refused(bad, where):
    mats = {"A": np.array(A2), "C": np.array([[1.0, 0.0]]), "E": np.array([[0.0], [1.0]])}
    mats[where][0, 0] = bad
    with pytest.raises(
        ValueError, match=rf"{where} has a non-finite entry .* at position \(0, 0\)"
    ):
        ut.Plant(mats["A"], mats["C"], E=mats["E"])


def test_non_numeric_is_refused():
    with pytest.raises(ValueError, match="A must be a real numeric matrix"):
        ut.Plant([["a", "b"], ["c", "d"]], [[1, 0]])


@pytest.mark.parametrize("dt", [-1, -0.5, float("nan"), float("inf"), "1", False])
def test_bad_dt(dt):
    with pytest.raises(ValueError, match="dt must be None"):
        ut.Plant(A2, [[1, 0]], dt=dt)


@pytest.mark.parametrize("dt, expected", [(None, None), (0, None), (True, True), (0.1, 0.1)])
def test_dt_conventions(dt, expected):
    plant = ut.Plant(A2, [[1, 0]], dt=dt)
    assert plant.dt == expected
    assert plant.is_discrete == (expected is not None)


def test_immutable():
    plant = ut.examples.pa9()
    with pytest.raises(AttributeError):
        plant.A = np.eye(3)
    with pytest.raises(ValueError):
        plant.A[0, 0] = 5.0  # read-only array
    src = np.array(A2)
    p2 = ut.Plant(src, [[1, 0]])
    src[0, 0] = 99.0
    assert p2.A[0, 0] == 0.0  # the plant holds its own copy


def test_one_dimensional_vectors():
    plant = ut.Plant(A2, [1, 0], E=[0, 1], B=[1, 1])
    assert plant.C.shape == (1, 2) and plant.E.shape == (2, 1) and plant.B.shape == (2, 1)


def test_from_statespace_splits_inputs():
    sys = ct.ss(
        A2,
        [[0, 1, 0], [1, 0, 0]],
        [[1, 0], [0, 1]],
        [[0, 0, 1], [0, 0, 0.5]],
        inputs=["u", "d", "v"],
    )
    plant = ut.Plant.from_statespace(sys, unknown=["d"], measurement=["v"])
    np.testing.assert_array_equal(plant.B, [[0], [1]])
    np.testing.assert_array_equal(plant.E, [[1], [0]])
    np.testing.assert_array_equal(plant.D, [[1], [0.5]])
    # and back: the inputs are [u; d; v]
    back = plant.as_statespace()
    np.testing.assert_array_equal(back.B, sys.B)
    np.testing.assert_array_equal(back.D, sys.D)


def test_from_statespace_errors():
    sys = ct.ss(A2, [[0, 1], [1, 0]], [[1, 0]], [[0, 1]], inputs=["u", "d"])
    with pytest.raises(ValueError, match="'d' feeds through to the output"):
        ut.Plant.from_statespace(sys, unknown=["d"])
    with pytest.raises(ValueError, match="no input named 'w'"):
        ut.Plant.from_statespace(sys, unknown=["w"])
    with pytest.raises(ValueError, match="control.StateSpace"):
        ut.Plant.from_statespace(np.eye(2), unknown=[0])


def test_discrete_round_trip():
    plant = ut.examples.dt_case_study()
    sys = plant.as_statespace()
    assert sys.dt == 1
    again = ut.Plant.from_statespace(sys, unknown=[0], measurement=[1])
    assert again == plant


def test_display():
    plant = ut.examples.pa9()
    text = str(plant)
    assert "PA9" in text and "E = " in text and "continuous-time" in text
    assert "<table" in plant._repr_html_()
