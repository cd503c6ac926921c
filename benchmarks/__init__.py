"""Timed benchmarks of warpcaustics; run ``python -m benchmarks.run --help``."""
