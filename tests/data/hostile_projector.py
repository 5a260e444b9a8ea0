"""A projector that ends its process (tests/test_api.py: the API runs it isolated)."""

import os


def exits(points, camera):
    os._exit(0)
