"""Scanned springs: read a measured point cloud, fit the paddle's mid-surface (``fit``) and write
the fitted surface and a spring file that uses it (``importer``)."""
