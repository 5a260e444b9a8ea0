"""Scenes: what is drawn and how it moves.

``model`` is the :class:`Scene` (objects, vertices, edges, faces, world points of
a frame), ``files`` reads the ``.scene`` text format, mesh files and the bundled
scenes into one, and ``frames`` (:class:`SceneRenderer`) is frame ``k`` of a
scene's motion through one camera, the scene-level entry to the pipeline.
"""
