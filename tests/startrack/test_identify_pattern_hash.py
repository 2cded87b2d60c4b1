"""Pattern look-ups of a calibrated camera (startrack.identify.pattern_hash) on random frames of the real sky.

Frames: every Hipparcos star with V <= 6 in a 16 deg, 1024 x 1024 pinhole field at a uniformly random
attitude, 0.1 px centroid noise (startrack.image.synthetic).  The look-ups alone (no pyramid after
them) are checked against the truth, against mirror images and random points, and against the
pyramid search of the same frames.
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from startrack.camera.model import Camera
from startrack.catalog.hipparcos import load_star_catalog
from startrack.catalog.navigation import load_navigation_catalog
from startrack.identify import StarIdentifier
from startrack.identify.pattern_catalog import PatternCatalog, PatternCatalogParams, build_level, candidates_per_lookup
from startrack.identify.pattern_hash import HASH_STARS, NO_PATTERNS, hash_search, pattern_arrays
from startrack.identify.scale_free import COMBINATIONS_BELOW
from startrack.identify.zones import SKY, cap
from startrack.image.synthetic import centroid_frame, random_attitude

SIGMA_PX = 0.1
ARCSEC = math.pi / 180.0 / 3600.0


@pytest.fixture(scope="module")
def setup():
    catalog = load_navigation_catalog()
    camera = Camera.from_fov(np.radians(16.0), 1024, 1024)
    stars = load_star_catalog(2000.0).brighter_than(6.0)
    return camera, stars, StarIdentifier(catalog, camera, centroid_sigma_px=SIGMA_PX)


def _look_up(identifier, frame, region=SKY):
    """hash_search alone on a frame: (ok, R_IS, centroid indices, HIP numbers)."""
    result = identifier.solve(frame.uv, frame.flux)  # the frame's directions, as the identifier orders them
    index = np.argsort(-frame.flux, kind="stable")
    features = identifier.features(identifier.camera.unproject(frame.uv[index]), index)
    context = identifier.strategies[-1].context
    ok, R_IS, obs_index, star_index, _, _ = hash_search(*features.arrays, context.patterns, region,
                                                        context.field_arrays)
    return ok, R_IS, index[obs_index], identifier.field.hip[star_index], result


def test_the_level_is_the_camera_field_and_n_h_counts_every_look_up(setup):
    camera, stars, identifier = setup
    patterns = identifier.strategies[-1].context.patterns
    cat_stars, keys, slots, width, base, n_combinations, cos_separation, n_h = patterns
    assert cat_stars.shape[1] == 4 and cat_stars.min() >= 0 and cat_stars.max() < len(identifier.field)
    assert np.all(np.diff(keys) >= 0) and 50_000 < keys.size < 200_000
    assert n_combinations == COMBINATIONS_BELOW[HASH_STARS] == 35
    assert math.isclose(math.acos(cos_separation), camera.fov_x / 20.0)  # rounding level: the cosine of this angle
    assert 0.0 < n_h / n_combinations < 100.0
    narrow = Camera.from_fov(np.radians(0.3), 1024, 1024)  # below the pattern catalog's 0.5 deg: no look-ups
    assert pattern_arrays(type(identifier.field)(identifier.catalog, narrow, stars.vectors[:50], stars.hip[:50],
                                                 stars.v_mag[:50])) is NO_PATTERNS
    few = type(identifier.field)(identifier.catalog, camera, stars.vectors[:3], stars.hip[:3], stars.v_mag[:3])
    assert pattern_arrays(few)[0].shape == (0, 4)  # no field of four stars: nothing to look up, no error
    field = identifier.field
    level = build_level(field.vectors, field.v_mag, camera.fov_x, PatternCatalogParams(camera.fov_x, camera.fov_x))
    assert level.width == width and n_h == pytest.approx(35 * level.per_lookup)


def test_candidates_per_lookup_counts_the_patterns_sharing_a_key():
    """Runs of 2, 1 and 3 equal keys: a pattern shares its key with (2*2 + 1*1 + 3*3) / 6 patterns on
    average, over the 32 keys a look-up visits."""
    assert candidates_per_lookup(np.array([4, 4, 7, 9, 9, 9])) == pytest.approx(32.0 * 14.0 / 6.0)
    assert candidates_per_lookup(np.zeros(0, np.int64)) == 0.0


def test_a_saved_pattern_catalog_reads_back_the_same(tmp_path):
    """The two levels of a 12-22 deg catalog over the stars to V 5: every field and array as built."""
    params = PatternCatalogParams(fov_min=12.0 * math.pi / 180.0, fov_max=22.0 * math.pi / 180.0, mag_limit=5.0)
    built = PatternCatalog.build(params, load_star_catalog())
    read = PatternCatalog.read(built.save(tmp_path / "patterns"))
    assert read.params == params and np.array_equal(read.ids, built.ids) and len(read.levels) == len(built.levels) == 2
    for a, b in zip(read.levels, built.levels):
        assert (a.fov, a.width, a.base, a.tolerance, a.per_lookup) == (b.fov, b.width, b.base, b.tolerance, b.per_lookup)
        assert a.per_lookup == candidates_per_lookup(b.keys) > 0.0
        assert all(np.array_equal(getattr(a, name), getattr(b, name)) for name in ("stars", "keys", "slots"))


def test_look_ups_identify_clean_frames_at_the_pyramids_attitude(setup):
    """On 80 random frames without false stars the look-ups alone identify >= 95 % (measured: all but a
    few whose brightest stars form no catalog pattern), every HIP right, the stars and the attitude those
    of the full identifier (the same verification refit) to 0.1"."""
    camera, stars, identifier = setup
    rng = np.random.default_rng(17)
    identified = 0
    for _ in range(80):
        q = random_attitude(rng)
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, q, rng, SIGMA_PX)
        ok, R_IS, centroid, hip, result = _look_up(identifier, frame)
        if not ok:
            continue
        identified += 1
        np.testing.assert_array_equal(frame.hip[centroid], hip)
        np.testing.assert_array_equal(np.sort(hip), np.sort(result.matched_hip))
        error = (Rotation.from_matrix(R_IS).inv() * Rotation.from_quat(q)).magnitude()
        assert error < 60.0 * ARCSEC
        assert (Rotation.from_matrix(R_IS).inv() * Rotation.from_quat(result.q_IS)).magnitude() < 0.1 * ARCSEC
    assert identified >= 76


def test_mirror_images_random_points_and_a_wrong_region_give_nothing(setup):
    camera, stars, identifier = setup
    rng = np.random.default_rng(18)
    for _ in range(40):
        q = random_attitude(rng)
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, q, rng, SIGMA_PX)
        mirrored = frame.uv.copy()
        mirrored[:, 0] = camera.width - 1.0 - mirrored[:, 0]
        assert not _look_up(identifier, type(frame)(mirrored, frame.flux, frame.hip, q, frame.missing_hip))[0]
        points = rng.uniform(0.0, camera.width - 1.0, (25, 2))
        assert not _look_up(identifier, type(frame)(points, np.sort(rng.uniform(1, 2, 25))[::-1], frame.hip, q,
                                                    frame.missing_hip))[0]
        opposite = -Rotation.from_quat(q).as_matrix()[:, 2]  # every catalog star of the frame outside the region
        assert not _look_up(identifier, frame, cap(opposite, np.radians(30.0)))[0]


def test_centroid_errors_too_large_for_the_bins_are_left_to_the_pyramid(setup):
    """With 0.7 px centroid noise (000 §5) eps exceeds half a bin for nearly every combination: the look-ups
    give no answer (never a wrong one) and the identifier still identifies through the pyramid search."""
    camera, stars, identifier = setup
    noisy = StarIdentifier(identifier.catalog, camera, centroid_sigma_px=0.7, field_stars=identifier.field)
    rng = np.random.default_rng(19)
    answered = 0
    for _ in range(30):
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, 0.7)
        ok, _, centroid, hip, result = _look_up(noisy, frame)
        assert result.ok and np.all(frame.hip[result.matches[:, 0]] == result.matches[:, 1])
        if ok:
            answered += 1
            np.testing.assert_array_equal(frame.hip[centroid], hip)
    assert answered <= 10
