"""Ring detection speed on 256 px faces, against skimage's sato ridge filter in the same run."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest


@pytest.mark.bench
def test_detect_rings_speed_256():
    from skimage.filters import sato

    from woodcam.detect import detect_rings
    from woodcam.synth import ring_eval_faces

    faces = [f.photo for f in ring_eval_faces(1000)]
    detect_rings(faces[0])                       # warm-up (imports, FFT plans)
    t_det, t_sato, cpu = [], [], []
    for photo in faces:
        t0, c0 = time.perf_counter(), time.process_time()
        detect_rings(photo)
        t_det.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        t0 = time.perf_counter()
        sato(photo.mean(axis=2) / 255.0, sigmas=(2, 3, 4), black_ridges=True)
        t_sato.append(time.perf_counter() - t0)
    det, base = float(np.median(t_det)), float(np.median(t_sato))
    load = os.getloadavg()[0]
    print(f"\ndetect_rings 256x256: median {det:.2f} s wall, {np.median(cpu):.2f} CPU-s per face; "
          f"skimage sato (3 scales) {base:.2f} s; "
          f"ratio {det / base:.1f}; load average {load:.1f} on {os.cpu_count()} cores")
    assert det / base < 20
