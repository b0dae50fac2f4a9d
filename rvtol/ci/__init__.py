"""Tolerance sign-off in CI: baseline comparison, gates, JUnit and Markdown, the summary.json schema.

::

    rvtol run STUDY --baseline DIR --junit junit.xml --markdown summary.md
    rvtol compare BASE NEW --junit junit.xml --markdown summary.md

* :mod:`rvtol.ci.gates` — the ``[[gate]]`` tables a study declares (read when
  the study loads; recorded in summary.json): ``kind = "requirements"`` (no
  requirement may get worse) and ``kind = "output"`` (a statistic of an output
  may not move by more than a stated amount);
* :mod:`rvtol.ci.differences` — the interval of a change (mean, σ, a
  percentile, the non-conforming fraction), paired on common random numbers or
  unpaired;
* :mod:`rvtol.ci.compare` — two runs (report folders, summaries or a run in
  memory): spec diff, per output the change with its paired and unpaired
  intervals and the gain, requirement verdict changes, the gates;
* :mod:`rvtol.ci.junit`, :mod:`rvtol.ci.markdown` — what CI systems read;
* :mod:`rvtol.ci.schema` — the published JSON Schema of summary.json
  (``rvtol/ci/summary.schema.json``) and its validation.

Nothing here imports the report layer: it works on summary.json and
samples.parquet, the published outputs of a run.
"""
