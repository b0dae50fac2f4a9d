"""The reproduction wing: each reference document's printed figures against rvtol.

One module per document (``docNNN_*.py``); the printed numbers live in
``data/reproduction/`` with their sources.  Nothing in the library imports
this package: it only uses the library.
"""
