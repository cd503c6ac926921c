"""Device code of the scene: the under-water camera's rays, G-buffer and splats."""
