"""Object catalogues and loaders."""
