"""Field comparisons: the model's irradiance fluctuations against published measurements, each a
data set registered by name (``warpcaustics field NAME SCENE --out DIR``):

- ``gernez2009`` (:mod:`.gernez2009`): CV against the sun's zenith and the wind at 3.2 m, 510 nm,
  8 mm collector (Gernez & Antoine 2009, BOUSSOLE).
- ``gernez2009_bands`` (:mod:`.gernez2009_bands`): the same CV at six bands, 443-683 nm, against the
  sun's zenith (their Fig. 10a): what of the CV depends on the wavelength.
- ``darecki2011`` (:mod:`.darecki2011`): CV against depth, 0.86-9.58 m, at 443/532/670 nm,
  2.5 mm collector (Darecki, Stramski & Sokolski 2011, Santa Barbara Channel).
- ``darecki2011_wind`` (:mod:`.darecki2011_wind`): CV against wind, 3.9-10.3 m/s, at about 1 m and
  six bands, 410-670 nm (the same paper's Fig. 13b).
- ``darecki2011_radiance`` (:mod:`.darecki2011_radiance`): the CV of the radiance in a 4.5° field
  of view against its zenith in the sun's plane, 0.54-0.93 m, 532 nm (the same paper's Fig. 15):
  the surface's slopes, seen by a radiance sensor at every texel.

Each renders its points as one resumable sweep (:mod:`.common`) and writes a CSV and a figure.
"""

from warpcaustics.batch.field.common import nested_cv, patch_variance, pooled_statistics
from warpcaustics.batch.field.darecki2011 import run_darecki2011
from warpcaustics.batch.field.darecki2011_radiance import run_darecki2011_radiance
from warpcaustics.batch.field.darecki2011_wind import run_darecki2011_wind
from warpcaustics.batch.field.gernez2009 import (
    POINT_KEYS,
    QUICK_OVERRIDES,
    Point,
    diffuse_fraction,
    direct_transmission,
    gernez2009_points,
    point_variants,
    run_gernez2009,
    select_points,
)
from warpcaustics.batch.field.gernez2009_bands import run_gernez2009_bands

DATASETS = {"gernez2009": run_gernez2009, "gernez2009_bands": run_gernez2009_bands,
            "darecki2011": run_darecki2011, "darecki2011_wind": run_darecki2011_wind,
            "darecki2011_radiance": run_darecki2011_radiance}
"""name → the function that runs its comparison."""

POINT_FLAGS = {"gernez2009": ("series", "zeniths", "sqrt_winds"), "gernez2009_bands": ("zeniths",),
               "darecki2011": ("depths",),
               "darecki2011_wind": ("winds",), "darecki2011_radiance": ("panels", "view_zeniths")}
"""name → the keywords of its function that choose which of the record's points to render
(``warpcaustics field``'s flags of the same names); each is a tuple, None for all."""

LONG_WAVES_DATASETS = ("gernez2009", "gernez2009_bands", "darecki2011")
"""The data sets whose function takes ``long_waves_m`` (``--long-waves``): a coarse patch of the
waves longer than the scene's, nested with it (default: gernez2009 and gernez2009_bands 128 m,
darecki2011 0, off)."""

__all__ = [
    "DATASETS", "LONG_WAVES_DATASETS", "POINT_FLAGS", "POINT_KEYS", "QUICK_OVERRIDES", "Point",
    "diffuse_fraction", "direct_transmission", "gernez2009_points", "point_variants", "pooled_statistics",
    "run_darecki2011", "run_darecki2011_radiance", "run_darecki2011_wind", "run_gernez2009",
    "run_gernez2009_bands", "select_points",
    "nested_cv", "patch_variance",
]
