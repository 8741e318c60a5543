"""Points spread over a pixel for anti-aliasing: the headless renders' samples and the viewer's
temporal jitter."""


def pixel_offsets(samples):
    """Where in its pixel each of a frame's `samples` samples lies, (x, y) in -0.5..0.5 (x right,
    y up): the pixel centre for one; else the first points of the Halton sequence in bases 2
    and 3, which cover the pixel evenly for any count (their mean is a box filter)."""
    if samples == 1:
        return [(0.0, 0.0)]
    return [(_radical_inverse(k, 2) - 0.5, _radical_inverse(k, 3) - 0.5) for k in range(1, samples + 1)]


def _radical_inverse(k, base):
    """k's digits in `base` mirrored about the point: the Halton sequence's k-th coordinate."""
    value, scale = 0.0, 1.0 / base
    while k:
        k, digit = divmod(k, base)
        value += digit * scale
        scale /= base
    return value
