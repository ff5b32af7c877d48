"""Image helpers the benches' scripts share: PFM reading and PSNR as `footprint verify` computes it
(mean over the RGB channels, peak 1)."""
import numpy as np


def pfm(path):
    """A colour PFM as an H x W x 3 float64 array, top row first (PFM rows run bottom to top)."""
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        a = np.frombuffer(f.read(), "<f4" if scale < 0 else ">f4").reshape(h, w, 3)
    return a[::-1].astype(np.float64)


def psnr(a, b):
    """PSNR of `a` against `b` over every channel, peak 1, dB."""
    return 10 * np.log10(1 / max(1e-20, float(((np.asarray(a, np.float64) - b) ** 2).mean())))
