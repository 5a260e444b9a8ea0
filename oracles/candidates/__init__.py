"""Candidates: what is judged, and how it is run.

The contract and loading ``FILE.py:FUNC`` (``candidate``); where a candidate runs
(``isolation``): a program over the candidate protocol (``protocol``,
``subprocess_candidate``, ``candidate_host``), core itself (``core_candidate``),
or a renderer's own frames from an exported job (``export``,
``frames_candidate``); another candidate's vertices drawn with core's raster
(``draw``); the caller's process state kept (``caller_state``).
"""
