"""Studies: a TOML file names a design, a spec, a model, analyses and requirements.

::

    [study]
    name = "lost_motion_rv80e"            # output folder reports/<name>/
    title = "..."
    description = "..."
    design = "../data/designs/rv80e_te.toml"      # optional, relative to this file
    spec = "../data/specs/rv80e_lost_motion.toml" # TOML, CSV or XLSX; or [[factor]] tables in this file; or a
                                          # list of files read as one spec (the product's and a test rig's)
    requirements = "../data/requirements/x.toml"  # optional; [[requirement]] here too
    # extends = "base.toml"               # or: take design, spec, mapping, models and requirements from a
                                          # study in this folder; give name, title, analyses, options here
    exploratory = false                   # true: the study checks no requirement on purpose (verdict
                                          # EXPLORATORY, exit 0); without requirements and without
                                          # it the verdict is NO REQUIREMENTS (exit 4)

    [model]
    kind = "lost_motion"                  # see rvtol.registry.MODELS
    # ... model parameters

    # or several models on the same samples (a composed study, rvtol.models.composite):
    # [study] mapping = "mapping.toml"    # optional file of [[quantity]] tables (or give them here)
    # [study] build = "build.toml"        # optional: how the reducer is built (rvtol.production.build):
                                          # selective fits, shim preloads, gauges; false: the parts as drawn
    # [[model]]
    # name = "torsion"                    # its outputs are named "torsion.<output>"
    # kind = "torsion_curve"
    # outputs = ["lost_motion"]           # optional: the outputs to keep
    # [model.inputs]                      # the declared mapping: input = expression of factors,
    # "delta_b[1,1]" = "needle_clearance" # quantities and earlier models' outputs (base units)

    [sampling]
    n = 10000
    method = "lhs"                        # random | lhs | sobol
    seed = 20261121
    # until_decided = true                # sample batches of n until every requirement is decided (rvtol.sequential)
    # max_n = 200000                      # ... or this many samples are drawn (default 20 n)

    [execution]
    executor = "process"                  # serial | process | dask
    workers = 2                           # default: every core
    chunk_size = 0                        # 0: automatic

    [report]
    pdf = true
    confidence = 0.95
    tables = ["xlsx"]                     # optional: samples and statistics also as csv and/or xlsx

    [[analysis]]
    kind = "local_sensitivity"            # see rvtol.registry.ANALYSES
    # ... analysis parameters

    [[gate]]                              # what a change may do against the accepted baseline
    kind = "requirements"                 # (rvtol run --baseline, rvtol compare): see rvtol.ci.gates

Loading (:func:`load_study`) reads and checks *everything* — files, keys,
units, names, the model and every analysis' parameters — before anything is
computed; :func:`run_study` then runs Monte Carlo and the analyses and
:func:`write_outputs` writes the report folder atomically.
"""
from .folder import MANIFEST, check_out_dir, foreign_files, written_files
from .load import (NotRunModel, Study, check_output_names, check_requirement_names, check_sequential, load_study,
                   model_warnings)
from .model import build_model
from .options import MAX_N_PER_BATCH, RunOptions, execution_keys, read_table_options
from .run import StudyContext, StudyResult, run_study
from .write import write_outputs, write_tables

__all__ = ["MANIFEST", "MAX_N_PER_BATCH", "NotRunModel", "RunOptions", "Study", "StudyContext", "StudyResult",
           "build_model", "check_out_dir", "check_output_names", "check_requirement_names", "check_sequential",
           "execution_keys", "foreign_files", "load_study", "model_warnings", "read_table_options", "run_study",
           "write_outputs", "write_tables", "written_files"]
