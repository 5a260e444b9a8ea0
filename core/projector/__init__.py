"""The projector pipeline: a vertex becomes a pixel.

``pipeline.render_frame`` reads top to bottom: model -> camera space and pixels
(``projection``), clipping against the frustum and the image (``clipping``),
triangulation, back faces and bounding spheres (``culling``), lens distortion
(``distortion``), the depth buffer (``zbuffer``, ``hidden_lines``), flat shading
(``shading``) and line pixels (``raster``). numpy only; the conventions are
stated once in :mod:`wirecheck.core.conventions`.
"""
