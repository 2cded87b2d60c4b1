"""The rotation floor of both packages (startrack.geometry.rotation and its compiled twin) against scipy's Rotation.

Every tolerance here is at the rounding level: exact identities of well-conditioned closed forms (round
trips, conversions) and compiled twins of the same operations."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from startrack.geometry import rotation as rot
from startrack.geometry import rotation_kernels as rotation_jit

RNG = np.random.default_rng(20261122)


def random_quats(n):
    return Rotation.random(n, random_state=7).as_quat()


def test_multiply_matches_scipy_composition():
    p, q = random_quats(50), random_quats(50)[::-1]
    expected = (Rotation.from_quat(p) * Rotation.from_quat(q)).as_matrix()
    np.testing.assert_allclose(rot.to_matrix(rot.multiply(p, q)), expected, atol=1e-14)


def test_round_trips_with_scipy():
    q = random_quats(100)
    np.testing.assert_allclose(rot.to_matrix(q), Rotation.from_quat(q).as_matrix(), atol=1e-14)
    phi = Rotation.from_quat(q).as_rotvec()
    np.testing.assert_allclose(rot.to_rotation_vector(q), phi, atol=1e-12)
    back = rot.from_rotation_vector(phi)
    np.testing.assert_allclose(np.abs(np.sum(back * q, axis=1)), 1.0, atol=1e-14)
    v = RNG.standard_normal((100, 3))
    np.testing.assert_allclose(rot.rotate(q, v), Rotation.from_quat(q).apply(v), atol=1e-13)


def test_small_rotation_vectors_use_the_series():
    phi = np.array([[1e-9, -2e-9, 3e-10], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(rot.to_rotation_vector(rot.from_rotation_vector(phi)), phi, atol=1e-20)


def test_nearest_rotation_is_scipys_orthogonalisation():
    """Markley's quaternion from a non-orthogonal matrix (scipy) is the Frobenius-nearest rotation."""
    R = Rotation.random(50, random_state=3).as_matrix()
    M = R + 0.05 * RNG.standard_normal((50, 3, 3))  # rounding level: SVD and Markley's eigenvector, same optimum
    np.testing.assert_allclose(rot.nearest_rotation(M), Rotation.from_matrix(M).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(rot.nearest_rotation(R), R, atol=1e-14)


def test_skew_is_the_cross_product():
    v, u = RNG.standard_normal((2, 20, 3))
    np.testing.assert_allclose(np.einsum("nij,nj->ni", rot.skew(v), u), np.cross(v, u), atol=1e-15)


def test_compiled_twin_equals_the_numpy_forms():
    p, q = random_quats(2)
    w = np.array([0.2, 0.1, -0.3])
    np.testing.assert_allclose(rotation_jit.quat_multiply(p, q), rot.multiply(p, q), atol=1e-15)
    np.testing.assert_allclose(rotation_jit.quat_to_matrix(q), rot.to_matrix(q), atol=1e-15)
    np.testing.assert_allclose(rotation_jit.quat_from_rotation_vector(w), rot.from_rotation_vector(w), atol=1e-15)
    np.testing.assert_allclose(rotation_jit.rotation_vector(q), rot.to_rotation_vector(q), atol=1e-13)
    np.testing.assert_allclose(rotation_jit.skew(w) @ p[:3], np.cross(w, p[:3]), atol=1e-15)


def test_compiled_quaternion_of_a_matrix_takes_every_pivot():
    """Near-identity (trace pivot) and ~180 deg about x, y, z (each diagonal pivot), plus random rotations."""
    angles = np.array([[1e-3, -2e-3, 5e-4], [3.1, 0.05, -0.02], [0.03, 3.1, 0.04], [-0.02, 0.01, 3.1]])
    q = np.vstack([rot.from_rotation_vector(angles), random_quats(50)])
    for R in rot.to_matrix(q):
        np.testing.assert_allclose(rotation_jit.quat_from_matrix(R), rot.from_matrix(R), atol=1e-15)


def test_quaternion_matrix_conversions_match_scipy():
    rotations = Rotation.random(500, random_state=1)
    R = rotations.as_matrix()
    q = rot.from_matrix(R)
    q_scipy = rotations.as_quat()
    q_scipy = np.where(q_scipy[:, 3:] < 0, -q_scipy, q_scipy)
    np.testing.assert_allclose(q, q_scipy, atol=1e-14)
    np.testing.assert_allclose(rot.to_matrix(q), R, atol=1e-14)
    for k in range(5):                       # the single-matrix fast path gives the same numbers
        np.testing.assert_allclose(rot.from_matrix(R[k]), q[k], atol=1e-15)
        np.testing.assert_allclose(rot.to_matrix(q[k]), R[k], atol=1e-15)


@pytest.mark.parametrize("axis", range(3))
def test_shepperd_at_180_degrees(axis):
    q = np.zeros(4)
    q[axis] = 1.0
    np.testing.assert_allclose(np.abs(rot.from_matrix(rot.to_matrix(q))), q, atol=1e-15)


def test_compiled_wahba_svd_is_the_nearest_rotation_of_the_attitude_profile():
    """rotation_jit.wahba_svd (Jacobi eigen-decomposition) equals the numpy SVD solution R_IS =
    nearest_rotation(Bᵀ), B = Σ obs_i ref_iᵀ, for noisy star sets."""
    R_IS = Rotation.random(20, random_state=5).as_matrix()
    for R in R_IS:
        ref = RNG.standard_normal((6, 3))
        ref /= np.linalg.norm(ref, axis=1, keepdims=True)
        obs = ref @ R + 1e-3 * RNG.standard_normal((6, 3))
        # rounding level: the Jacobi sweeps stop at an off-diagonal 1e-17 of the diagonal (converged), the rest is
        # rounding amplified by the eigen-gaps of BᵀB
        np.testing.assert_allclose(rotation_jit.wahba_svd(ref, obs), rot.nearest_rotation((obs.T @ ref).T), atol=1e-12)
