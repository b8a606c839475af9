"""Platform-independent fingerprints of a pushbroom simulation's arrays.

A sha256 of float arrays holds only on the platform that wrote it: numpy's SIMD loops of
sin/cos/exp differ in the last bit between CPU generations (AVX2, AVX-512), and the digests of
main written on one machine failed on a SkylakeX one with the same code. So integer and boolean
arrays are hashed exactly, and float arrays are summarised (shape, sum, sum of |x|, eight
samples) and compared at 1e-9 relative: a change of the simulation shows, rounding does not.
"""

import hashlib

import numpy as np


def arrays(obs, truth) -> dict:
    """Every observation and truth array of one simulation, by name."""
    lines = obs.lines
    out = {
        "point": lines.point,
        "band": lines.band,
        "t_s": lines.t_s,
        "xy_px": lines.xy_px,
        "xyz_nav_m": lines.xyz_nav_m,
        "rpy_nav_rad": lines.rpy_nav_rad,
        "xyz_rate_nav_m_s": lines.xyz_rate_nav_m_s,
        "rpy_rate_nav_rad_s": lines.rpy_rate_nav_rad_s,
        "gcp_index": obs.gcp_index,
        "gcp_xyz_m": obs.gcp_xyz_m,
        "lever_arm_m": obs.lever_arm_m,
        "node_prior_mean": obs.node_prior_mean,
        "t_span_s": np.asarray(obs.t_span_s),
        "strips": np.asarray(truth.strips, float),
        "strip": truth.strip,
        "cp_index": truth.cp_index,
        "outlier": truth.outlier,
        "xy_true_px": truth.xy_true_px,
        "error_t_s": truth.error_t_s,
        "error_samples": truth.error_samples,
    }
    out.update({f"truth.{k}": truth.values[k] for k in sorted(truth.values)})
    return {k: np.asarray(v) for k, v in out.items() if v is not None}


def fingerprint(obs, truth) -> dict:
    """name -> {"shape", "sha256"} (integers, booleans) or {"shape", "summary"} (floats)."""
    fp = {}
    for name, a in arrays(obs, truth).items():
        a = np.ascontiguousarray(a)
        entry = {"shape": list(a.shape), "dtype": a.dtype.kind}
        if a.dtype.kind in "iub":
            entry["sha256"] = hashlib.sha256(a.astype(np.int64).tobytes()).hexdigest()
        else:
            x = a.astype(np.float64).ravel()
            idx = np.linspace(0, max(x.size - 1, 0), 8).astype(int) if x.size else []
            entry["summary"] = [float(x.sum()), float(np.abs(x).sum())] + [float(x[i]) for i in idx]
        fp[name] = entry
    return fp


def assert_same(fp: dict, ref: dict, rtol: float = 1e-9) -> None:
    assert sorted(fp) == sorted(ref), (sorted(fp), sorted(ref))
    for name in ref:
        a, b = fp[name], ref[name]
        assert a["shape"] == b["shape"] and a["dtype"] == b["dtype"], name
        if "sha256" in b:
            assert a["sha256"] == b["sha256"], name
        else:
            sa, sb = np.array(a["summary"]), np.array(b["summary"])
            scale = max(np.abs(sb).max(), 1e-300)
            np.testing.assert_allclose(sa, sb, rtol=rtol, atol=rtol * scale, err_msg=name)
