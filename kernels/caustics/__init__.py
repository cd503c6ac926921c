"""Device code of the caustic methods, one module per method."""
