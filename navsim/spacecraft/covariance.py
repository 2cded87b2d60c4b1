"""What the spacecraft kind offers the covariance-based tools: the attitude kind's summary quantities (about the
first head's boresight) and their errors from a run's series, for Monte Carlo trade sweeps; its linear covariance
analysis is not built (a campaign measures the same): :func:`covariance_analysis` says so."""

import functools

from navsim.attitude.covariance import COVARIANCE_QUANTITIES, run_errors
from navsim.spacecraft.build import mountings
from startrack import InputError
from startrack import rotation as rot

#: The error sources of a covariance analysis: none (it is not built).
COVARIANCE_SOURCES = {}
__all__ = ["COVARIANCE_QUANTITIES", "COVARIANCE_SOURCES", "covariance_analysis", "covariance_run_errors"]


def covariance_analysis(scenario, split=False, star_catalog=None):
    """The spacecraft kind has no linear covariance analysis: an InputError naming what does the job."""
    raise InputError(f"{scenario.source}: a spacecraft scenario has no linear covariance analysis; run a Monte Carlo "
                     "campaign (navsim montecarlo), whose summary pools the same errors and the NEES")


def covariance_run_errors(scenario):
    """The errors of a run series that make the summary quantities, about the first head's boresight."""
    return functools.partial(run_errors, rot.to_matrix(mountings(scenario)[0][0]))
