"""Device-side code of warpcaustics: ``@wp.kernel``, ``@wp.func`` and kernel factories only.

Installed as :mod:`warpcaustics.kernels`; import it as ``from warpcaustics.kernels import refract``,
never as a bare ``kernels`` (a PyPI package of that name exists).
"""
