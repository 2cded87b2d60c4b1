"""The campaign statistics of spacecraft runs: the attitude kind's (errors pooled over every steady frame, the
spread of the runs' RMS, the run-averaged NEES, divergent runs, gyro calibration) and each head's spread of
cross-boresight and roll RMS, its availability and the normalised errors of its mounting states."""

import numpy as np

from navsim.attitude.campaign import pool as attitude_pool
from navsim.pooling import spread


def pool(finished, settle):
    """The fields of a :class:`~navsim.spacecraft.records.CampaignSummary` from the finished runs
    [(index, summary, series), ...] and the settling time [s]."""
    out = attitude_pool(finished, settle)
    summaries = [summary for _, summary, _ in finished]
    heads = []
    for h, first in enumerate(summaries[0]["heads"]):
        per_run = [s["heads"][h] for s in summaries]
        entry = {"name": first["name"], "availability": spread([r["availability"] for r in per_run]),
                 "cross_boresight_rms_arcsec": spread([r["cross_boresight_rms_arcsec"] for r in per_run]),
                 "roll_rms_arcsec": spread([r["roll_rms_arcsec"] for r in per_run]),
                 "roll_to_cross_boresight": spread([r["roll_to_cross_boresight"] for r in per_run])}
        if "mounting_arcsec" in first:
            z = np.array([r["mounting_arcsec"]["normalised_error"] for r in per_run])
            entry["mounting_normalised_error"] = {"rms": [float(v) for v in np.sqrt(np.mean(z**2, axis=0))],
                                                  "within_3_sigma": float(np.mean(np.abs(z) <= 3.0))}
        if "image" in first:
            images = [r["image"] for r in per_run]
            entry["image"] = {key: int(sum(i[key] for i in images)) for key in
                              ("hits", "frames_with_hits", "frames_lost_with_hits", "frames_lost_without_hits",
                               "wrong_identifications")}
        heads.append(entry)
    out["heads"] = heads
    return out
