"""Numeric libraries pinned to the same kernels on every x86-64 machine, and what ran.

numpy and OpenBLAS choose their SIMD kernels when they load, by the CPU they find: on a
machine with AVX-512, numpy's float32 ``power``/``exp``/``log``… and OpenBLAS's matrix
products take other kernels than on an AVX2 machine, and their results differ in the last
bit (measured here: forcing OpenBLAS's Sandybridge kernels on this AVX2 machine changes
every camera image of a smoke run). Both read their choice from the environment once, at
load, so this module sets it before numpy is imported:

- ``OPENBLAS_CORETYPE=Haswell`` (AVX2 + FMA kernels) where the CPU has AVX2 and FMA, which
  every AVX-512 CPU has too; elsewhere OpenBLAS keeps its own choice, recorded.
- ``NPY_DISABLE_CPU_FEATURES`` += the AVX-512 groups (numpy then dispatches to its AVX2
  kernels, as on an AVX2 machine).
- OpenBLAS on one thread (``OPENBLAS_NUM_THREADS=1``, and :func:`pin_blas_threads` once numpy
  is loaded): a threaded matrix product splits its columns by thread, and the columns at a
  split's edge take a tail kernel that sums in another order, so a 1 × 31 by 31 × N product
  changes in the last bit between one and two threads (measured: 3 of 32 400 values). dask's
  workers run OpenBLAS on one thread, so a serial run must too for its bytes to match a pooled one.

A value the user set is kept. What cannot be pinned from Python — Mitsuba's ray tracer
(Embree picks its AVX2 or AVX-512 kernels itself) and onnxruntime's CPU kernels (MLAS,
likewise) — is recorded by :func:`numeric_provenance`, and docs/performance.md ("Bytes
across machines") says what is therefore identical across machines and what only agrees.

Nothing here imports numpy: :mod:`metricscenes` imports this module first.
"""

from __future__ import annotations

import os
import sys
from importlib.metadata import PackageNotFoundError, version

OPENBLAS_CORETYPE = "Haswell"
BLAS_THREADS = "1"
NUMPY_AVX512_GROUPS = ("X86_V4", "AVX512_ICL", "AVX512_SPR")
BYTE_DECIDING_PACKAGES = ("mitsuba", "drjit", "numpy", "scipy", "onnxruntime", "zarr", "numcodecs",
                          "colour-science", "colour-demosaicing", "pillow", "faster-coco-eval", "pycocotools")
"""The packages whose versions decide the bytes of a collection, a capture or a score."""


def cpu_flags() -> frozenset[str]:
    """The CPU's feature flags as Linux reports them (empty where /proc/cpuinfo is absent)."""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as f:
            for line in f:
                if line.startswith("flags"):
                    return frozenset(line.split(":", 1)[1].split())
    except OSError:
        pass
    return frozenset()


def cpu_vendor() -> str:
    """The CPU's vendor as Linux reports it ('GenuineIntel', 'AuthenticAMD'; '' where unknown).

    With the ISA class it names the kind of machine whose ray-tracer bytes agree: Embree's
    approximate reciprocals (``rcpps``, ``vrcp14ps``) are specified only to a relative error,
    so two vendors' CPUs may round them differently, and smoke's radiance does differ between
    an Intel and an AMD AVX-512 machine (tests/golden)."""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as f:
            for line in f:
                if line.startswith("vendor_id"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return ""


def isa_class(flags: frozenset[str] | None = None) -> str:
    """'avx512', 'avx2' or 'other': the kernel class Embree and onnxruntime take here."""
    flags = cpu_flags() if flags is None else flags
    if {"avx512f", "avx512vl", "avx512bw", "avx512dq"} <= flags:
        return "avx512"
    if {"avx2", "fma"} <= flags:
        return "avx2"
    return "other"


def pin_numeric_libraries(environ=os.environ) -> bool:
    """Set the kernel choices above unless numpy is already loaded; True if they hold."""
    if "numpy" in sys.modules:
        return pins_hold(environ)
    if {"avx2", "fma"} <= cpu_flags():
        environ.setdefault("OPENBLAS_CORETYPE", OPENBLAS_CORETYPE)
    environ["OPENBLAS_NUM_THREADS"] = BLAS_THREADS  # not the user's: bytes must not depend on it
    disabled = environ.get("NPY_DISABLE_CPU_FEATURES", "").replace(",", " ").split()
    environ["NPY_DISABLE_CPU_FEATURES"] = " ".join(dict.fromkeys(disabled + list(NUMPY_AVX512_GROUPS)))
    return pins_hold(environ)


def pin_blas_threads() -> None:
    """OpenBLAS on one thread in this process, also where numpy was loaded before us."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=int(BLAS_THREADS), user_api="blas")


def pins_hold(environ=os.environ) -> bool:
    disabled = set(environ.get("NPY_DISABLE_CPU_FEATURES", "").replace(",", " ").split())
    blas_ok = environ.get("OPENBLAS_CORETYPE") == OPENBLAS_CORETYPE or not {"avx2", "fma"} <= cpu_flags()
    return blas_ok and set(NUMPY_AVX512_GROUPS) <= disabled


def package_versions() -> dict[str, str | None]:
    """Installed version of each byte-deciding package (None: not installed)."""
    out = {}
    for name in BYTE_DECIDING_PACKAGES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = None
    return out


def numeric_provenance() -> dict:
    """What decided the bytes of this process's numbers: versions, ISA class, kernels."""
    from threadpoolctl import threadpool_info

    blas = sorted({str(i.get("architecture")) for i in threadpool_info() if i.get("internal_api") == "openblas"})
    return {
        "versions": package_versions(),
        "isa_class": isa_class(),
        "openblas_coretype": blas,
        "numpy_disabled_features": os.environ.get("NPY_DISABLE_CPU_FEATURES", ""),
        "pinned": pins_hold(),
    }
