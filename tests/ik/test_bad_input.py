"""Bad input to the IK interface: clear errors naming the argument."""

from __future__ import annotations

import numpy as np
import pytest

import serialkin.ik as ik
from serialkin.errors import InputError, InputTypeError
from serialkin.spatial import rotx


@pytest.fixture
def T(ur5):
    """A reachable UR5 target."""
    return ur5.fk(ur5.random_q(seed=0))


def test_non_orthonormal_rotation(ur5, T):
    """A target whose rotation block is not orthonormal is rejected, naming target."""
    bad = T.copy()
    bad[:3, :3] *= 1.01
    with pytest.raises(InputError, match="target.*orthonormal"):
        ur5.ik(bad)


def test_improper_rotation(ur5, T):
    """A reflection (det −1) is not a rotation."""
    bad = T.copy()
    bad[:3, 0] *= -1
    with pytest.raises(InputError, match="det"):
        ur5.ik(bad)


def test_bad_last_row(ur5, T):
    """A last row other than [0, 0, 0, 1] is rejected."""
    bad = T.copy()
    bad[3, 0] = 0.2
    with pytest.raises(InputError, match=r"last row must be \[0, 0, 0, 1\]"):
        ur5.ik(bad)


def test_nan_target(ur5, T):
    """NaN in a target is rejected, single or batch."""
    bad = T.copy()
    bad[0, 3] = np.nan
    with pytest.raises(InputError, match="target must be finite"):
        ur5.ik(bad)
    with pytest.raises(InputError, match="target must be finite"):
        ur5.ik(np.stack([T, bad]))
    with pytest.raises(InputError, match="target must be finite"):
        ur5.ik([0.1, np.inf, 0.2])


def test_bad_target_shapes(ur5, T):
    """Shapes other than pose / position / planar are rejected with the accepted list."""
    for bad in (np.zeros(5), np.zeros((3, 4)), np.zeros((2, 2, 4, 4)), np.zeros((2, 2, 3)), "pose"):
        with pytest.raises((InputError, InputTypeError), match="target"):
            ur5.ik(bad)


def test_planar_target_on_spatial_robot(ur5):
    """An (x, y) target needs a planar robot."""
    with pytest.raises(InputError, match="not planar"):
        ur5.ik(np.array([0.3, 0.2]))


def test_q0_wrong_size(ur5, T):
    """q0 with the wrong number of joints names q0 and the expected size."""
    with pytest.raises(InputError, match="q0 has 5 values.*6 joints"):
        ur5.ik(T, q0=np.zeros(5))
    with pytest.raises(InputError, match=r"q0 must have shape \(6,\) or \(2, 6\)"):
        ur5.ik(np.stack([T, T]), q0=np.zeros((3, 6)))
    with pytest.raises(InputError, match=r"q0 must have shape \(6,\) for one target"):
        ur5.ik(T, q0=np.zeros((2, 6)))


def test_q0_outside_limits(puma):
    """q0 outside the limits is an error naming the joint and its range."""
    T = puma.fk(np.zeros(6))
    q0 = np.zeros(6)
    q0[4] = 3.0
    with pytest.raises(InputError, match=r"q0 is outside the joint limits: q0\[4\]"):
        puma.ik(T, q0=q0)
    assert puma.ik(T, q0=q0, respect_limits=False, seed=0).success


def test_q0_nan(ur5, T):
    """A NaN in q0 is rejected."""
    with pytest.raises(InputError, match="q0 must be finite"):
        ur5.ik(T, q0=np.array([0, 0, np.nan, 0, 0, 0.0]))


def test_unknown_method_lists_names(ur5, T):
    """An unknown method name raises and lists every available method."""
    with pytest.raises(InputError, match="unknown method 'lmm'") as err:
        ur5.ik(T, method="lmm")
    for name in ik.available_methods():
        assert repr(name) in str(err.value)
    assert "Did you mean 'lm'" in str(err.value)


def test_mask_errors(ur5, T, puma):
    """A mask selecting nothing, of the wrong size, negative, or beyond the target kind."""
    with pytest.raises(InputError, match="mask selects no task coordinate"):
        ur5.ik(T, mask=[0, 0, 0, 0, 0, 0])
    with pytest.raises(InputError, match="mask must have 6 entries"):
        ur5.ik(T, mask=[1, 1, 1])
    with pytest.raises(InputError, match="mask weights must be >= 0"):
        ur5.ik(T, mask=[1, 1, 1, -1, 0, 0])
    with pytest.raises(InputError, match=r"mask selects \['wx'\] but a position target"):
        puma.ik(np.array([0.3, 0.1, 0.2]), mask=[1, 1, 1, 1, 0, 0])
    with pytest.raises(InputError, match="mask must be finite"):
        ur5.ik(T, mask=[1, 1, 1, np.nan, 0, 0])


def test_tolerance_errors(ur5, T):
    """The tolerance must be a finite number > 0."""
    for bad in (-1e-6, 0.0, np.inf):
        with pytest.raises(InputError, match="tol must be a finite number > 0"):
            ur5.ik(T, tol=bad)
    with pytest.raises(InputTypeError, match="tol must be a real number"):
        ur5.ik(T, tol="small")


def test_budget_errors(ur5, T):
    """max_iter >= 1 and restarts >= 0, both integers."""
    with pytest.raises(InputError, match="max_iter must be >= 1"):
        ur5.ik(T, max_iter=0)
    with pytest.raises(InputError, match="restarts must be >= 0"):
        ur5.ik(T, restarts=-1)
    with pytest.raises(InputTypeError, match="max_iter must be an integer"):
        ur5.ik(T, max_iter=10.5)


def test_unknown_option_lists_options(ur5, T):
    """A misspelt option names the method's accepted options."""
    with pytest.raises(InputError, match=r"unknown option\(s\) \['dampign'\].*damping"):
        ur5.ik(T, method="dls", dampign=0.1)


def test_bad_option_values(ur5, T):
    """Method options are validated (damping >= 0, windows >= 1)."""
    with pytest.raises(InputError, match="damping must be a finite number >= 0"):
        ur5.ik(T, method="dls", damping=-1.0)
    with pytest.raises(InputError, match="stall_window must be >= 1"):
        ur5.ik(T, method="lm", stall_window=0)


def test_bad_seed_and_flags(ur5, T):
    """The seed must be None / int / Generator; respect_limits must be a bool."""
    with pytest.raises(InputTypeError, match="seed must be None, an int or a numpy Generator"):
        ur5.ik(T, seed="abc")
    with pytest.raises(InputTypeError, match="respect_limits must be True or False"):
        ur5.ik(T, respect_limits="yes")


def test_method_target_kind_mismatch(ur5, T):
    """A method that does not accept a target kind says which kinds it accepts."""
    from serialkin.ik.registry import MethodSpec, register_method

    spec = register_method(MethodSpec(name="_pose_only_test", family="jacobian",
                                      summary="test", limits="test", targets=("pose",),
                                      kernel=ik.METHODS["lm"].kernel))
    try:
        with pytest.raises(InputError, match="does not accept position targets"):
            ur5.ik(np.array([0.3, 0.1, 0.2]), method=spec.name)
    finally:
        from serialkin.ik import registry

        registry._REGISTRY.pop(spec.name)


def test_small_rotation_noise_is_accepted(ur5):
    """Rotations orthonormal to 1e-9 (e.g. from a file) are accepted."""
    T = ur5.fk(ur5.random_q(seed=1))
    T[:3, :3] = T[:3, :3] @ (np.eye(3) + 1e-10 * np.ones((3, 3)))
    assert ur5.ik(T, seed=0).success
    T2 = np.eye(4)
    T2[:3, :3] = rotx(0.3)
    T2[:3, 3] = [0.3, 0.2, 0.3]
    assert np.isfinite(ur5.ik(T2, seed=0, restarts=3).q).all()
