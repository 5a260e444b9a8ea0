"""Fault names: what is wrong, from the vertices (``diagnose``), from the images
alone (``image_diagnose``) and from a lens (``lens_diagnose``).
"""
