import numpy as np
import pytest


def diamond_image(n, pixel_size, z, period=2.5):
    """Checkerboard of diamonds (|1/2 - frac(u)| + |1/2 - frac(v)| < 1/2)
    sliding with z, as a stand-in for a phasor-noise slice."""
    yy, xx = np.mgrid[0:n, 0:n] * pixel_size
    u = np.mod((xx + z) / period, 1.0)
    v = np.mod((yy - z) / period, 1.0)
    return (np.abs(0.5 - u) + np.abs(0.5 - v)) < 0.5


@pytest.fixture
def diamonds():
    return diamond_image
