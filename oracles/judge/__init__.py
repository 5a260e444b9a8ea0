"""The judge: a case's verdict from the candidate's and the references' outputs.

The case cameras (``cases``), one case run frame by frame (``case``), the
metrics (``metrics``, ``segment_pixels``, ``line_ties``), every tolerance and its
reason (``tolerances``), the verdict and its reasons (``verdict``) and the
rules a gate follows (``gate``: never pass on nothing).
"""
