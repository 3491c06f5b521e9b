"""Extraction of the C-60 contact primitives from its STEP files (needs OpenCASCADE)."""
