"""wirecheck core: a from-scratch wireframe projector (numpy only).

The conventions are stated once, in :mod:`core.conventions`.
"""
