"""Nonsmooth Moreau--Jean reference solver (no scene, engine or report imports)."""
