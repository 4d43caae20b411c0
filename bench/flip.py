"""LDR-FLIP image difference, numpy only.

Implemented from the description and formulas of
  P. Andersson, J. Nilsson, T. Akenine-Moeller, M. Oskarsson, K. Astroem,
  M. D. Fairchild: "FLIP: A Difference Evaluator for Alternating Images",
  Proc. ACM Comput. Graph. Interact. Tech. 3(2), article 15, 2020.

Colour pipeline: both images in the linear opponent space YyCxCz, each
channel filtered by the paper's contrast sensitivity functions (sums of
Gaussians in visual degrees), back to linear RGB clamped to [0, 1], CIELAB
with the Hunt adjustment (a, b scaled by L/100), HyAB distance, raised to
q_c = 0.7 and remapped to [0, 1] against the Hunt-adjusted green-blue
distance (p_c = 0.4, p_t = 0.95). Feature pipeline: edges (first derivative
of a Gaussian) and points (second derivative) of the unfiltered luminance,
sigma = w / 2 degrees with w = 0.082; the larger of the two magnitude
differences, scaled by 1/sqrt(2), raised to q_f = 0.5. Per pixel:
FLIP = colour error ** (1 - feature error). Image borders are extended by
repeating the edge pixels. All filters are separable (the blue-yellow CSF as
a sum of two separable Gaussians); computed in float64.

Our renders are linear radiance; the displayed image is clamp(x, 0, 1)
sRGB-encoded (the PNG writer at exposure 0, without the 8-bit rounding), so
FLIP is computed on the clamped linear values (decoding the sRGB display
values gives them back). Validated against NVIDIA's flip-evaluator; see
bench/README.md.
"""
import math

import numpy as np

# Viewing conditions of the paper: 0.7 m from a 0.7 m wide monitor with 3840
# pixels across, i.e. ~67.02 pixels per degree of visual angle.


def pixels_per_degree(distance_m=0.7, width_px=3840, width_m=0.7):
    return distance_m * (width_px / width_m) * math.pi / 180.0


DEFAULT_PPD = pixels_per_degree()

# ---------------------------------------------------------------- colour spaces

# sRGB primaries and D65 white point (chromaticities, IEC 61966-2-1).
_PRIMARIES = np.array([[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]])
_WHITE_XY = np.array([0.3127, 0.3290])


def _xyz_of(xy):
    x, y = xy
    return np.array([x / y, 1.0, (1.0 - x - y) / y])


def _rgb_to_xyz_matrix():
    columns = np.stack([_xyz_of(p) for p in _PRIMARIES], axis=1)
    scale = np.linalg.solve(columns, _xyz_of(_WHITE_XY))  # white = RGB (1, 1, 1)
    return columns * scale


RGB_TO_XYZ = _rgb_to_xyz_matrix()
XYZ_TO_RGB = np.linalg.inv(RGB_TO_XYZ)
WHITE = RGB_TO_XYZ @ np.ones(3)  # XYZ of the display's white, Y = 1


def srgb_encode(linear):
    x = np.clip(np.nan_to_num(linear, nan=0.0), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def srgb_decode(encoded):
    c = np.asarray(encoded, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, np.power((c + 0.055) / 1.055, 2.4))


def _linear_to_ycxcz(rgb):
    """Linear RGB -> YyCxCz (CIELAB's axes without the cube root)."""
    n = (rgb @ RGB_TO_XYZ.T) / WHITE
    return np.stack([116.0 * n[..., 1] - 16.0,
                     500.0 * (n[..., 0] - n[..., 1]),
                     200.0 * (n[..., 1] - n[..., 2])], axis=-1)


def _ycxcz_to_linear(ycc):
    y = (ycc[..., 0] + 16.0) / 116.0
    n = np.stack([y + ycc[..., 1] / 500.0, y, y - ycc[..., 2] / 200.0], axis=-1)
    return (n * WHITE) @ XYZ_TO_RGB.T


def _lab_f(t):
    d = 6.0 / 29.0
    return np.where(t > d ** 3, np.cbrt(t), t / (3 * d * d) + 4.0 / 29.0)


def _hunt_lab(rgb):
    """Linear RGB -> CIELAB with the Hunt adjustment of a and b."""
    f = _lab_f((rgb @ RGB_TO_XYZ.T) / WHITE)
    L = 116.0 * f[..., 1] - 16.0
    a = 500.0 * (f[..., 0] - f[..., 1])
    b = 200.0 * (f[..., 1] - f[..., 2])
    return np.stack([L, 0.01 * L * a, 0.01 * L * b], axis=-1)


def _hyab(p, q):
    d = p - q
    return np.abs(d[..., 0]) + np.hypot(d[..., 1], d[..., 2])


# ---------------------------------------------------------------- constants

# Contrast sensitivity functions, per YyCxCz channel: sum of (a, b) terms,
# a * exp(-b * f^2) in frequency f [cycles/degree], i.e. in space
# a * sqrt(pi / b) * exp(-pi^2 x^2 / b) with x in degrees.
CSF = (((1.0, 0.0047),),                    # achromatic (a2 = 0)
       ((1.0, 0.0053),),                    # red-green (a2 = 0)
       ((34.1, 0.04), (13.5, 0.025)))       # blue-yellow
CSF_MAX_B = 0.04  # widest term; the paper's other b2 = 1e-5 is narrower
Q_C, P_C, P_T = 0.7, 0.4, 0.95
W_FEATURE, Q_F = 0.082, 0.5

_CMAX = float(_hyab(_hunt_lab(np.array([0.0, 1.0, 0.0])),
                    _hunt_lab(np.array([0.0, 0.0, 1.0]))) ** Q_C)


# ---------------------------------------------------------------- filtering

def _correlate(stack, taps, axis):
    """Correlate each channel k of `stack` (K x H x W) with its own odd-length
    1-D kernel taps[:, k] along `axis` (1 = rows, 2 = columns), repeating
    edge pixels beyond the border."""
    r = taps.shape[0] // 2
    pad = [(0, 0)] * 3
    pad[axis] = (r, r)
    p = np.pad(stack, pad, mode="edge")
    n = stack.shape[axis]
    w = taps[:, :, None, None]
    out = w[0] * (p[:, :n] if axis == 1 else p[:, :, :n])
    for i in range(1, taps.shape[0]):
        out += w[i] * (p[:, i:i + n] if axis == 1 else p[:, :, i:i + n])
    return out


def _separable(stack, tx, ty):
    return _correlate(_correlate(stack, tx, 2), ty, 1)


def _csf_kernels(ppd):
    """The 2-D kernel of channel c is sum over its terms of
    weight * outer(taps, taps), normalised to sum 1. Returns the channel each
    term filters, its weight and its taps (one column per term)."""
    radius = int(math.ceil(3.0 * math.sqrt(CSF_MAX_B / (2 * math.pi ** 2)) * ppd))
    x = np.arange(-radius, radius + 1) / ppd  # degrees
    channel, weight, taps = [], [], []
    for c, terms in enumerate(CSF):
        parts = [(a * math.sqrt(math.pi / b), np.exp(-(math.pi ** 2) * x * x / b)) for a, b in terms]
        total = sum(w * t.sum() ** 2 for w, t in parts)
        for w, t in parts:
            channel.append(c)
            weight.append(w / total)
            taps.append(t)
    return channel, np.array(weight), np.stack(taps, axis=1)


def _feature_kernels(ppd):
    """Gaussian, first and second derivative taps (sigma = w/2 degrees): the
    Gaussian sums to 1; each derivative's positive taps sum to 1 and its
    negative taps to -1."""
    sigma = 0.5 * W_FEATURE * ppd
    radius = int(math.ceil(3.0 * sigma))
    x = np.arange(-radius, radius + 1, dtype=np.float64)
    g = np.exp(-x * x / (2 * sigma * sigma))
    d1 = -x * g
    d2 = (x * x / (sigma * sigma) - 1.0) * g

    def balance(k):
        return np.where(k > 0, k / k[k > 0].sum(), k / -k[k < 0].sum())
    return g / g.sum(), balance(d1), balance(d2)


# ---------------------------------------------------------------- FLIP

def _displayed(img):
    """Linear render -> the linear values of its displayed (clamped) image."""
    a = np.asarray(img, dtype=np.float64)
    if a.ndim != 3 or a.shape[2] < 3:
        raise ValueError(f"expected an H x W x 3 image, got shape {a.shape}")
    return np.clip(np.nan_to_num(a[..., :3], nan=0.0), 0.0, 1.0)


def _colour_error(ref, test, ppd):
    channel, weight, taps = _csf_kernels(ppd)
    n = len(channel)
    # Both images' channels, one column per CSF term: [ref terms, test terms].
    stack = np.concatenate([np.moveaxis(_linear_to_ycxcz(ref), -1, 0)[channel],
                            np.moveaxis(_linear_to_ycxcz(test), -1, 0)[channel]])
    both = np.concatenate([taps, taps], axis=1)
    filtered = _separable(stack, both, both) * np.concatenate([weight, weight])[:, None, None]
    labs = []
    for k in (0, n):
        ycc = np.zeros(ref.shape)
        for j, c in enumerate(channel):
            ycc[..., c] += filtered[k + j]
        labs.append(_hunt_lab(np.clip(_ycxcz_to_linear(ycc), 0.0, 1.0)))
    d = _hyab(labs[0], labs[1]) ** Q_C
    pc = P_C * _CMAX
    return np.where(d < pc, d * (P_T / pc), P_T + (d - pc) / (_CMAX - pc) * (1.0 - P_T))


def _feature_error(ref, test, ppd):
    g, d1, d2 = _feature_kernels(ppd)
    # Luminance relative to white, (Yy + 16) / 116, in [0, 1].
    lum = np.stack([(img @ RGB_TO_XYZ[1]) / WHITE[1] for img in (ref, test)])
    # Along x: d1, d2 and g of both images; along y: g after d1 and d2 (the
    # x derivatives), d1 and d2 after g (the y derivatives).
    along_x = _correlate(np.concatenate([lum, lum, lum]),
                         np.stack([d1, d1, d2, d2, g, g], axis=1), 2)
    along_x = np.concatenate([along_x, along_x[4:6]])
    f = _correlate(along_x, np.stack([g, g, g, g, d1, d1, d2, d2], axis=1), 1)
    edge = np.hypot(f[0:2], f[4:6])   # [ref, test]
    point = np.hypot(f[2:4], f[6:8])
    diff = np.maximum(np.abs(edge[0] - edge[1]), np.abs(point[0] - point[1]))
    return (diff / math.sqrt(2.0)) ** Q_F


def flip_map_linear(test, reference, ppd=DEFAULT_PPD):
    """Per-pixel LDR-FLIP (H x W, in [0, 1]) between two images given as
    linear RGB in [0, 1] (no clamping done here)."""
    ref = np.asarray(reference, dtype=np.float64)
    tst = np.asarray(test, dtype=np.float64)
    if ref.shape != tst.shape:
        raise ValueError(f"image shapes differ: {tst.shape} vs {ref.shape}")
    return _colour_error(ref, tst, ppd) ** (1.0 - _feature_error(ref, tst, ppd))


def flip_map(test, reference, ppd=DEFAULT_PPD):
    """Per-pixel LDR-FLIP between two linear-radiance renders (H x W x 3),
    each displayed as clamp(x, 0, 1) in sRGB."""
    return flip_map_linear(_displayed(test), _displayed(reference), ppd)


def flip_map_srgb(test, reference, ppd=DEFAULT_PPD):
    """Per-pixel LDR-FLIP between two sRGB-encoded images in [0, 1]."""
    return flip_map_linear(srgb_decode(np.clip(test, 0, 1)[..., :3]),
                           srgb_decode(np.clip(reference, 0, 1)[..., :3]), ppd)


def mean_flip(test, reference, ppd=DEFAULT_PPD):
    """Mean LDR-FLIP between two linear-radiance renders (H x W x 3)."""
    return float(np.mean(flip_map(test, reference, ppd)))
