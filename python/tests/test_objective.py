"""flexkin.overall_objective: the overall step's metric, its gradient and Hessian."""
import numpy as np
import pytest

import flexkin

TERMS = ["squared", "squared_weighted", "rotation", "joint_angle", "l2", "l2_weighted"]


def configuration(dim, seed=0):
    rng = np.random.default_rng(seed)
    old = flexkin.parabola(links=6) if dim == 2 else flexkin.helix(links=6, link_length=0.8)
    lengths = np.linalg.norm(np.diff(old, axis=0), axis=1)
    new = old + rng.normal(scale=0.05, size=old.shape)
    return lengths, old, new


@pytest.mark.parametrize("weights", [{"squared": 1}, {"rotation": 0.5, "squared_weighted": 1},
                                     {"l2": 1}, {"squared": 1, "joint_angle": 2}])
def test_the_report_of_a_step_is_the_objective_at_its_result(weights):
    old = flexkin.parabola(links=10)
    new, report = flexkin.overall_step(old, [0.2, 0.1], options=weights)
    lengths = flexkin.Chain(old).lengths
    assert report.converged
    value = flexkin.overall_objective(weights, lengths, old, new)
    assert value == pytest.approx(report.objective, rel=1e-12, abs=1e-15)
    assert flexkin.overall_objective(flexkin.ObjectiveWeights(**weights), lengths, old, new) == value


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("term", TERMS)
def test_gradient_and_hessian_match_finite_differences(dim, term):
    lengths, old, new = configuration(dim, seed=len(term))
    weights = {term: 1.0}
    value, gradient, hessian = flexkin.overall_objective(weights, lengths, old, new, hessian=True)
    n = len(lengths)
    assert gradient.shape == (n * dim,) and hessian.shape == (n * dim, n * dim)
    assert value == flexkin.overall_objective(weights, lengths, old, new)
    again = flexkin.overall_objective(weights, lengths, old, new, gradient=True)
    assert again[0] == value and np.array_equal(again[1], gradient)
    if term == "joint_angle" and dim == 3:                      # ignored for 3D chains
        assert value == 0 and not gradient.any() and not hessian.any()
        return
    assert np.allclose(hessian, hessian.T, atol=1e-9)
    h = 1e-6
    for k in range(n * dim):
        plus, minus = new.copy(), new.copy()
        plus[1 + k // dim, k % dim] += h
        minus[1 + k // dim, k % dim] -= h
        f_plus = flexkin.overall_objective(weights, lengths, old, plus, gradient=True)
        f_minus = flexkin.overall_objective(weights, lengths, old, minus, gradient=True)
        assert (f_plus[0] - f_minus[0]) / (2 * h) == pytest.approx(gradient[k], rel=1e-5,
                                                                 abs=1e-7)
        column = (f_plus[1] - f_minus[1]) / (2 * h)
        assert np.allclose(column, hessian[:, k], rtol=1e-4, atol=1e-5), k


def test_point_zero_does_not_count_and_a_still_chain_costs_nothing():
    lengths, old, new = configuration(2)
    moved = new.copy()
    moved[0] += 10.0
    for term in TERMS:
        assert flexkin.overall_objective({term: 1}, lengths, old, old) == 0.0
        value = flexkin.overall_objective({term: 1}, lengths, old, new)
        assert value > 0
    assert flexkin.overall_objective({"squared": 1}, lengths, old, moved) == \
        flexkin.overall_objective({"squared": 1}, lengths, old, new)
    expected = np.sum((new[1:] - old[1:]) ** 2)
    assert flexkin.overall_objective({"squared": 1}, lengths, old, new) == pytest.approx(expected)
