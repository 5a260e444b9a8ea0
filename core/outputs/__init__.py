"""Where a file is written: PNG, ASCII, GIF and MP4 bytes, and the staging that
makes a run's outputs appear together or not at all, never over a user's file.
"""
