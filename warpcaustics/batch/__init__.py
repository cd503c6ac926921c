"""Many renders: sweeps (local or Ray), water-type studies, field comparisons, method comparisons and the
frame statistics they report."""
