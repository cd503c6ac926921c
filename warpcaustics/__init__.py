"""warpcaustics: sunlight under moving water, simulated with NVIDIA Warp kernels.

``import warpcaustics`` stays light: Warp, colour-science and OpenEXR load on first use.
"""

from __future__ import annotations

__version__ = "0.1.0"

__all__ = ["load_scene", "render", "Renderer", "RenderResult", "Scene", "WarpcausticsError", "ConfigError",
           "DeviceError", "__version__"]


def __dir__() -> list[str]:
    """The public names (those loaded on first use included), so ``dir(warpcaustics)`` and editors
    show them."""
    return sorted(set(__all__) | set(globals()))


def __getattr__(name: str):
    # Lazy public surface: the config layer is cheap, the pipeline pulls in Warp.
    if name in ("load_scene", "Scene"):
        from warpcaustics import scene

        return getattr(scene, name)
    if name in ("render", "Renderer", "RenderResult"):
        from warpcaustics import pipeline

        return getattr(pipeline, name)
    if name in ("WarpcausticsError", "ConfigError", "DeviceError"):
        from warpcaustics import errors

        return getattr(errors, name)
    raise AttributeError(f"module 'warpcaustics' has no attribute {name!r}")
