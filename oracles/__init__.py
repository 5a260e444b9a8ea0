"""Independent reference implementations (oracles) for cross-checking ``core``.

``convert`` translates a :class:`core.camera.Camera` into the conventions of
OpenCV and pyrender (and back); ``opencv_oracle`` projects points with
``cv2.projectPoints``; ``pyrender_oracle`` rasterises wireframes (and, for
hidden lines and shaded frames, faces: coverage, linear depth, triangle ids)
with pyrender/OSMesa (Mesa's llvmpipe); ``faces`` builds world points of
several objects, fans and back faces from the stated rules. None of them
imports core's matrices or projection code: the Camera is read only as a
specification. ``plots`` draws the report's figures (worst.gif, per-frame plots).
"""
