"""Predicted sub-catalog recognition with its 4 redundant neighbours (000 §4) and the full-sky fall-back."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from startrack.camera.model import Camera
from startrack.catalog.hipparcos import load_star_catalog
from startrack.catalog.navigation import load_navigation_catalog
from startrack.geometry.sphere import vector_to_radec
from startrack.identify import Prior, StarIdentifier
from startrack.identify.pairs import SubCatalogPairs
from startrack.image.synthetic import centroid_frame, random_attitude

DEG = np.pi / 180.0


@pytest.fixture(scope="module")
def setup():
    catalog = load_navigation_catalog()
    camera = Camera.from_fov(16.0 * DEG, 1024, 1024, circular_fov=True)  # 000 §5: 16 deg circular field
    stars = load_star_catalog(2000.0).brighter_than(6.0)
    return catalog, camera, stars


def _disturbed_boresight(q_IS, error, rng):
    """(ra, dec) of the boresight of q_IS moved by ``error`` [rad] in a random direction."""
    axis = rng.normal(size=3)
    boresight = Rotation.from_quat(q_IS).as_matrix()[:, 2]
    axis -= (axis @ boresight) * boresight
    moved = Rotation.from_rotvec(error * axis / np.linalg.norm(axis)).apply(boresight)
    return tuple(float(x) for x in vector_to_radec(moved))


def test_cells_are_the_predicted_sub_catalog_and_its_neighbours(setup):
    catalog, camera, _ = setup
    identifier = StarIdentifier(catalog, camera, methods=("subcatalog",))
    sub = identifier.strategies[0]
    ra, dec = 1.2, 0.4
    cells = list(sub.cells(ra, dec))
    assert cells[0] == catalog.sub_catalog_index(ra, dec)
    assert set(cells[1:]) == set(catalog.redundant_neighbours(ra, dec).tolist()) - {cells[0]}


def test_recognition_up_to_the_stated_tolerance(setup):
    """Prior boresight errors up to 6.97 deg (000 §5, 3 sigma), frames of guide stars, at most 7 stars used:
    recognised in the predicted sub-catalog or one of its 4 redundant neighbours, never a false match."""
    catalog, camera, stars = setup
    identifier = StarIdentifier(catalog, camera, centroid_sigma_px=0.5, methods=("subcatalog",), max_stars=7)
    rng = np.random.default_rng(697)
    for error_deg in np.linspace(0.0, 6.97, 25):
        frame = centroid_frame(camera, catalog.guide_vectors, catalog.guide_hip, catalog.guide_v_mag,
                               random_attitude(rng), rng, 0.5)
        prior = Prior(boresight=_disturbed_boresight(frame.q_IS, error_deg * DEG, rng))
        result = identifier.solve(frame.uv, frame.flux, prior)
        assert result.ok, (error_deg, result.reason)
        assert result.method == "subcatalog"
        np.testing.assert_array_equal(frame.hip[result.matches[:, 0]], result.matches[:, 1])


def test_far_prior_falls_back_to_the_full_sky(setup):
    catalog, camera, stars = setup
    identifier = StarIdentifier(catalog, camera, centroid_sigma_px=0.2)
    rng = np.random.default_rng(40)
    frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, 0.2)
    result = identifier.solve(frame.uv, frame.flux, Prior(boresight=_disturbed_boresight(frame.q_IS, 40 * DEG, rng)))
    assert result.ok and result.method == "lost_in_space"
    only_sub = StarIdentifier(catalog, camera, centroid_sigma_px=0.2, methods=("subcatalog",))
    far = only_sub.solve(frame.uv, frame.flux, Prior(boresight=_disturbed_boresight(frame.q_IS, 40 * DEG, rng)))
    assert far.status == "no_match"
    assert only_sub.solve(frame.uv, frame.flux).status == "no_match"  # no prior: nothing to search


def test_sub_catalog_tables_hold_exactly_its_pairs(setup):
    """The contiguous per-sub-catalog tables the search reads are the sub-catalog's pattern pairs of 000 §2.3
    (distances in single precision: within 1.5e-8 rad (3 mas), far inside any gate)."""
    catalog, _, _ = setup
    tables = SubCatalogPairs(catalog)
    for b in (0, 137, len(catalog.base_vectors) // 2, len(catalog.base_vectors) - 1):
        pairs = catalog.sub_catalog_pairs(b)
        theta, first, second = tables.arrays(b)[:3]
        np.testing.assert_allclose(theta, catalog.pair_theta[pairs], rtol=0, atol=2e-8)  # [rad], single precision
        np.testing.assert_array_equal(first, catalog.pair_i[pairs])
        np.testing.assert_array_equal(second, catalog.pair_j[pairs])
        assert np.all(np.diff(theta) >= 0.0) and len(pairs) > 0


def test_frames_with_two_guide_stars_are_found_in_the_region(setup):
    """Keep only 2 guide stars of each frame: no sub-catalog can identify it; the field stars within
    2 rho_sub of the predicted boresight can, with no full-sky search."""
    catalog, camera, stars = setup
    identifier = StarIdentifier(catalog, camera, centroid_sigma_px=0.2, methods=("subcatalog",))
    guide = set(catalog.guide_hip.tolist())
    rng = np.random.default_rng(23)
    for _ in range(5):
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, 0.2, n_false=2)
        is_guide = np.array([h in guide for h in frame.hip])
        keep = ~is_guide | (np.cumsum(is_guide) <= 2)
        prior = Prior(boresight=_disturbed_boresight(frame.q_IS, 3.0 * DEG, rng))
        result = identifier.solve(frame.uv[keep], frame.flux[keep], prior)
        assert result.ok and result.method == "subcatalog", result.reason
        np.testing.assert_array_equal(frame.hip[keep][result.matches[:, 0]], result.matches[:, 1])
