"""The seed's statistics over the nine points or cubes of one model and pass (spec §2.4).

The mean drops the single highest and the single lowest value (Ch. 4 L1579: the mean of 7 of 9).
The seed does not say over which values its standard deviation runs; the tables here use the
sample standard deviation (ddof = 1) of the same kept values, and summary() also gives it over
all values (docs/mixing.md, "Statistics").
"""
import math

import numpy as np


def kept(values):
    """The values without one highest and one lowest (all of them when fewer than 3), NaNs
    (e.g. phi_v with no small particle) excluded."""
    v = np.sort(np.asarray(values, dtype=float)[~np.isnan(values)])
    return v[1:-1] if len(v) >= 3 else v


def trimmed_mean(values):
    return float(np.mean(kept(values)))


def trimmed_mean_error(values):
    """The standard error of trimmed_mean (Tukey & McLaughlin 1963): the std of the winsorised
    values (the highest and the lowest replaced by their neighbours, as the trim drops them) over
    (1 - 2g) sqrt(n), g = 1/n the fraction trimmed from each end; the plain std / sqrt(n) when
    fewer than 3 values leave nothing trimmed."""
    v = np.sort(np.asarray(values, dtype=float)[~np.isnan(values)])
    n = len(v)
    if n < 3:
        return float(np.std(v, ddof=1) / math.sqrt(n)) if n > 1 else float("nan")
    w = v.copy()
    w[0], w[-1] = v[1], v[-2]
    return float(np.std(w, ddof=1) / ((1.0 - 2.0 / n) * math.sqrt(n)))


def trimmed_std(values):
    k = kept(values)
    return float(np.std(k, ddof=1)) if len(k) > 1 else float("nan")


def summary(values):
    v = np.asarray(values, dtype=float)
    ok = v[~np.isnan(v)]
    return {"mean": trimmed_mean(v), "std": trimmed_std(v), "n_kept": int(len(kept(v))),
            "std_all": float(np.std(ok, ddof=1)) if len(ok) > 1 else float("nan"),
            "mean_all": float(np.mean(ok)) if len(ok) else float("nan"), "n": int(len(v))}


def cell(mean, std, fmt):
    """A table cell "mean ± std" in fmt, or "—" when there is no mean."""
    if mean is None or (isinstance(mean, float) and math.isnan(mean)):
        return "—"
    return (fmt % mean) + " ± " + (fmt % std)
