"""The cameras of *Ray Tracing in One Weekend*, run backwards: which pixel's ray hits a point.

A ray tracer has no projection function; its camera says which ray each pixel
shoots. The projector that matches it sends a point along the ray through the
camera centre and reads where it crosses the viewport plane.

v4.0 (2024, ``camera.h``)::

    viewport_height = 2 tan(vfov / 2) * focal_length
    viewport_width  = viewport_height * W / H
    pixel_delta_u = viewport_u / W,   pixel_delta_v = viewport_v / H     (v points down)
    pixel00_loc   = viewport_upper_left + 0.5 (pixel_delta_u + pixel_delta_v)
    ray(i, j)     = pixel00_loc + i pixel_delta_u + j pixel_delta_v - center

so pixel (i, j) looks through its own centre: exactly the contract.

v3.2 (2020, main.cc + camera.h)::

    u = i / (W - 1),  v = j / (H - 1)          (j counted from the bottom row)
    ray(u, v) = lower_left_corner + u horizontal + v vertical - origin

The first and last pixels look through the viewport's *edges*, so the image
spans W - 1 pixel steps across the full field of view: a scale of (W - 1) / W
horizontally and (H - 1) / H vertically, up to half a pixel at the borders.
Neither version has an orthographic camera or a far plane; points behind the
camera, nearer than ``near`` or beyond ``far`` are dropped here as the
contract asks.
"""

import numpy as np


def _camera_space(points, camera):
    w = -np.asarray(camera.forward, float)  # RTIOW's w points backwards
    u = np.cross(camera.up, w)
    u = u / np.linalg.norm(u)
    v = np.cross(w, u)
    d = np.asarray(points, float) - camera.position
    return d @ u, d @ v, -(d @ w)  # right, up, depth


def project_v4(points, camera):
    x, y, depth = _camera_space(points, camera)
    W, H = camera.width, camera.height
    vh = 2 * np.tan(np.radians(camera.fov_y_deg) / 2)  # focal_length 1
    vw = vh * W / H
    with np.errstate(divide="ignore", invalid="ignore"):
        xs, ys = x / depth, y / depth  # on the plane at distance 1
    i = (xs + vw / 2) / (vw / W) - 0.5  # pixel00 is half a step in
    j = (vh / 2 - ys) / (vh / H) - 0.5
    px = np.stack([i, j], axis=1)
    px[(depth < camera.near) | (depth > camera.far)] = np.nan
    return px


def project_v3(points, camera):
    x, y, depth = _camera_space(points, camera)
    W, H = camera.width, camera.height
    vh = 2 * np.tan(np.radians(camera.fov_y_deg) / 2)
    vw = vh * W / H
    with np.errstate(divide="ignore", invalid="ignore"):
        xs, ys = x / depth, y / depth
    u = (xs + vw / 2) / vw
    v = (ys + vh / 2) / vh  # from the bottom
    i = u * (W - 1)
    j = (H - 1) - v * (H - 1)  # row 0 is the top of the file
    px = np.stack([i, j], axis=1)
    px[(depth < camera.near) | (depth > camera.far)] = np.nan
    return px
