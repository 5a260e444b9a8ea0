"""Reports: report.json / .md / .html (``report``), figures (``plots``), JUnit
XML (``junit``), and the console's number formats and progress bar.
"""
