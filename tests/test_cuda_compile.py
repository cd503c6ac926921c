"""The CUDA side of every kernel compiles, with or without a GPU.

No GPU has been lent to the sessions that wrote most of these kernels, so the ``device`` fixture's
CUDA cases are skipped here. Warp's wheel carries NVRTC, which compiles a module's CUDA code to
PTX without a driver: this catches what only the CUDA code generator rejects (a tile FFT whose
block leaves a thread fewer than two elements, say). Whether the kernels are right on a GPU is for
the ``device`` tests on a machine that has one (``benchmarks/gpu_checks.sh``).
"""

import importlib
import pkgutil

import pytest
import warp as wp

import warpcaustics.kernels as kernels
from warpcaustics.kernels.water.ocean import row_fft_kernel
from warpcaustics.water import cuda_fft_block_dim

ARCH = 90
"""sm_90 (Hopper), the GPU benchmarks/gpu_checks.sh is written for."""


def _nvrtc_archs() -> set:
    wp.init()
    from warp._src import context  # the archs Warp's NVRTC can target (no public accessor)

    return set(getattr(context.runtime, "nvrtc_supported_archs", None) or ())


pytestmark = pytest.mark.skipif(ARCH not in _nvrtc_archs(), reason="Warp's NVRTC cannot target sm_90 here")

MODULES = sorted(m.name.removeprefix("warpcaustics.kernels.") for m in pkgutil.walk_packages(
    kernels.__path__, "warpcaustics.kernels.") if not m.ispkg)  # stage subpackages included


@pytest.mark.parametrize("name", MODULES)
def test_kernel_module_compiles_for_cuda(name, tmp_path):
    module = importlib.import_module(f"warpcaustics.kernels.{name}")
    if not any(isinstance(v, wp.Kernel) for v in vars(module).values()):
        pytest.skip(f"kernels/{name}.py holds only functions (compiled with the modules that call them)")
    wp.compile_aot_module(module, arch=ARCH, module_dir=tmp_path, use_ptx=True)
    assert list(tmp_path.glob("*.ptx"))


@pytest.mark.parametrize("inverse", [False, True], ids=["forward", "inverse"])
def test_row_fft_compiles_for_cuda_at_its_launch_block(inverse, tmp_path):
    """The ocean's tile FFT at the smallest size, with the block the CUDA launch uses (Warp refuses
    the module's default of 256 threads for 64 points)."""
    n = 64
    options = row_fft_kernel(n, inverse).module.options
    default = options["block_dim"]
    options["block_dim"] = cuda_fft_block_dim(n)
    try:
        wp.compile_aot_module(row_fft_kernel(n, inverse).module, arch=ARCH, module_dir=tmp_path, use_ptx=True)
    finally:
        options["block_dim"] = default  # the module is shared (functools.cache) with the CPU runs
    assert list(tmp_path.glob("*.ptx"))
