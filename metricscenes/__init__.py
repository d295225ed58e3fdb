"""metricscenes: seeded metric driving scenes rendered as spectral radiance.

Stages (each its own module, data flows one way):
manifest -> plan -> scene (Mitsuba) -> render -> store (zarr) -> SpectralScene.
"""

# Before anything imports numpy: the same numeric kernels on every x86-64 machine.
from metricscenes.numeric_pins import pin_numeric_libraries

pin_numeric_libraries()

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("metricscenes")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

from metricscenes.radiance import RadianceLayer, SpectralScene  # noqa: E402
from metricscenes.spectral import WAVELENGTHS_NM  # noqa: E402
from metricscenes.numeric_pins import pin_blas_threads  # noqa: E402

pin_blas_threads()  # numpy is loaded now

__all__ = ["__version__", "WAVELENGTHS_NM", "RadianceLayer", "SpectralScene"]
