"""Independent reference implementations (oracles) for cross-checking ``core``.

``convert`` translates a :class:`core.camera.Camera` into the conventions of
OpenCV and pyrender (and back); ``opencv_oracle`` projects points with
``cv2.projectPoints``; ``pyrender_oracle`` rasterises wireframes with
pyrender/OSMesa (Mesa's llvmpipe). None of them imports core's matrices or
projection code: the Camera is read only as a specification.
"""
