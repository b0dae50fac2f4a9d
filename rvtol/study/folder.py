"""The report folder a run may write: its name's length, what a run may replace (an empty folder or an
earlier rvtol report, never a user's files) and the manifest of what a run wrote."""
from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError
from ..runguard import NAME_MAX_BYTES

#: the longest report folder name: ``.NAME.tmp-<12 hex>`` and ``.NAME.old-<12 hex>`` are made beside it
MAX_FOLDER_NAME_BYTES = NAME_MAX_BYTES - len(".") - len(".tmp-") - 12


def check_out_dir(out_dir: str | Path) -> Path:
    """Check that ``out_dir`` may receive a report; raise :class:`InputError` (key ``--out``) if not.

    A report replaces only an absent or empty folder or an earlier rvtol report folder (one with an
    rvtol ``summary.json``) — never other files, the current folder or one of its parents.
    """
    out = Path(out_dir)
    where = str(out_dir)
    full = out.resolve()
    cwd = Path.cwd().resolve()
    if full == cwd or full in cwd.parents:
        raise InputError("refusing to replace the current folder or one of its parents; name a subfolder",
                         file=where, key="--out")
    if len(out.name.encode()) > MAX_FOLDER_NAME_BYTES:
        raise InputError(f"the folder's name is {len(out.name.encode())} bytes long: at most {MAX_FOLDER_NAME_BYTES} "
                         f"(a file name's {NAME_MAX_BYTES}, less the temporary names rvtol gives beside it)",
                         file=where, key="--out")
    if out.exists():
        if not out.is_dir():
            raise InputError("exists and is not a folder", file=where, key="--out")
        if any(out.iterdir()) and not _is_report_folder(out):
            raise InputError("exists and is not an rvtol report folder (no rvtol summary.json in it); "
                             "choose another --out or empty it", file=where, key="--out")
        foreign = foreign_files(out)
        if foreign:
            shown = ", ".join(foreign[:5]) + (f" and {len(foreign) - 5} more" if len(foreign) > 5 else "")
            raise InputError(f"holds files rvtol did not write ({shown}); a run replaces the whole folder: move them "
                             "elsewhere first", file=where, key="--out")
    return out


#: the list of the files a report folder's run wrote (written last, in the same atomic step)
MANIFEST = ".rvtol-files"
#: files of a report folder written before the manifest existed
_KNOWN = ("summary.json", "samples.parquet", "report.html", "report.pdf", "comparison.json", "requirements.csv",
          "per_unit.csv", "samples.csv", "samples.xlsx", "statistics.csv", "statistics.xlsx")


def foreign_files(folder: Path) -> list[str]:
    """The entries of an rvtol report folder that rvtol did not write (its manifest, or the known names)."""
    try:
        known = set((folder / MANIFEST).read_text(encoding="utf-8").split("\n")) | {MANIFEST}
    except (OSError, UnicodeDecodeError):
        known = set(_KNOWN)
    return sorted(p.name for p in folder.iterdir() if p.name not in known)


def _is_report_folder(path: Path) -> bool:
    try:
        return json.loads((path / "summary.json").read_text()).get("format", "").startswith("rvtol-summary/")
    except (OSError, ValueError, AttributeError, RecursionError):
        return False


def written_files(folder: Path) -> list[str]:
    """The files a written report folder holds besides report.html, as its manifest lists them (what the run wrote:
    the PDFs, tables, the requirements' CSV, comparison.json and every analysis' own files)."""
    names = (Path(folder) / MANIFEST).read_text(encoding="utf-8").split("\n")
    return sorted(n for n in names if n and n not in ("report.html", MANIFEST))
