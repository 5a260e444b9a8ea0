"""Mesh datasets: the files of ``--scene DIR`` / ``--scene-list`` (``dataset``), one
task per mesh (``dataset_run``), where tasks run (``executors``: this process, a
process pool, a Dask cluster) and a dataset's summary (``dataset_report``).
"""
