"""What ``startrack detect`` prints: one line per detection (the detector's columns, then the position fit's with
its σ per axis and their correlation), or the fit of each star for the JSON, which is strict (no NaN)."""

import json

import numpy as np

#: The flags of a position fit (startrack.image.psf_fit).
FIT_FLAGS = ("outlier", "edge", "saturated", "failed", "blended")


def fit_dict(fits, i):
    """The fit of star ``i`` of ``fits`` (:class:`startrack.image.psf_fit.StarFits`) for the JSON."""
    return {"u": float(fits.uv[i, 0]), "v": float(fits.uv[i, 1]), "cov_uv_px2": fits.cov[i].tolist(),
            "flux_dn": float(fits.flux[i]), "background_dn": float(fits.background[i]), "chi2": float(fits.chi2[i]),
            "dof": int(fits.dof[i]), **{flag: bool(getattr(fits, flag)[i]) for flag in FIT_FLAGS}}


def strict_json(value):
    """``json.dumps`` of ``value`` with its non-finite numbers as null (strict JSON)."""
    return json.dumps(json.loads(json.dumps(value), parse_constant=lambda name: None))


def print_stars(found, fits):
    """One line per detection of ``found``: the detector's columns, then (``fits`` not None) the fit's position,
    σ per axis [px] and their correlation, and the flags."""
    fitted = "" if fits is None else f" {'fit_u_px':>10} {'fit_v_px':>10} {'sig_u':>6} {'sig_v':>6} {'rho':>5}"
    print(f"{'#':>4} {'u_px':>10} {'v_px':>10} {'flux_dn':>10} {'peak_dn':>8} {'npix':>5} {'snr':>7}{fitted}  flags")
    for i in range(len(found)):
        flags = [name for name, on in (("saturated", found.saturated[i]), ("edge", found.edge[i])) if on]
        columns = ""
        if fits is not None:
            sigma_u, sigma_v = np.sqrt(np.diag(fits.cov[i]))
            rho = fits.cov[i, 0, 1] / (sigma_u * sigma_v)
            columns = f" {fits.uv[i, 0]:>10.3f} {fits.uv[i, 1]:>10.3f} {sigma_u:>6.3f} {sigma_v:>6.3f} {rho:>5.2f}"
            flags += [f"fit-{name}" for name in FIT_FLAGS if getattr(fits, name)[i]]
        print(f"{i:>4} {found.u[i]:>10.3f} {found.v[i]:>10.3f} {found.flux[i]:>10.1f} {found.peak[i]:>8.0f} "
              f"{found.npix[i]:>5d} {found.snr[i]:>7.1f}{columns}  {','.join(flags)}")
