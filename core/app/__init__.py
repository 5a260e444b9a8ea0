"""The ``renderer`` application over the projector.

``cli`` parses and calls; ``guard`` turns any failure into one stderr line and
an exit status; ``run`` renders, composes (``compose``) and writes every frame
of a run with its per-frame records (``report``); ``compare``, ``trace``,
``profile`` and ``viewer`` are ``--compare``, ``--trace-vertex``, ``--profile``
and ``--interactive``; ``motion_plot`` draws ``--plots``.
"""
