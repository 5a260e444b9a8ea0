"""The independent references: OpenCV's ``projectPoints`` for vertices
(``opencv_oracle``) and pyrender on OSMesa or EGL for pixels and depth
(``pyrender_oracle``), with their own conversions from our camera (``convert``)
and their own world points and faces (``faces``). Nothing here borrows core's
projection math.
"""
