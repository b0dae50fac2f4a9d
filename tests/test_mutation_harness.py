"""The mutation harness's own rule (tests/mutation.py): the mutants it skips as annotations are those in
annotations a module never evaluates, and no others (spans counted by hand)."""
import pytest

from mutation import annotation_spans

SOURCE = ("x: int | None = 1\n"
          "def f(a: str | None, *b: int, c: float = 2 | 3) -> tuple[int, ...]:\n"
          "    return a | b\n")


def test_annotations_are_skipped_only_where_they_are_never_evaluated():
    spans = annotation_spans("from __future__ import annotations\n" + SOURCE)
    assert sorted(spans) == [((2, 3), (2, 13)),                       # x: int | None
                             ((3, 9), (3, 19)), ((3, 25), (3, 28)),   # a: str | None, *b: int
                             ((3, 33), (3, 38)), ((3, 51), (3, 66))]  # c: float, -> tuple[int, ...]
    # the default value 2 | 3 and the body's a | b are code: not in any span
    assert not any(a <= (3, 41) < b or a <= (4, 13) < b for a, b in spans)
    assert annotation_spans(SOURCE) == []       # evaluated at definition time: mutants there are real


def test_only_lines_inside_a_function_body_count_as_run_when_called():
    """A mutant judged by the tests that ran its line alone must be on a line run only when a function is called:
    module constants, defaults, decorators, class attributes and one-line defs are evaluated at import (counted by
    hand: lines 1–13 below)."""
    from mutation import function_body_lines

    source = ("LIMIT = 3\n"                       # 1 import time
              "@decorate(2)\n"                    # 2 import time
              "def f(a,\n"                        # 3 import time (the signature)
              "      b=LIMIT + 1):\n"             # 4 import time (a default)
              "    x = a + b\n"                   # 5 body
              "    def g(c=x):\n"                 # 6 a def line: judged by every file (safe, if stricter than needed)
              "        return c * 2\n"            # 7 body
              "    return g()\n"                  # 8 body
              "class K:\n"                        # 9 import time
              "    size = 4\n"                    # 10 import time (a class attribute)
              "    def m(self):\n"                # 11 import time
              "        return self.size\n"        # 12 body
              "def h(y=5): return y\n")           # 13 a one-line def: its default is evaluated at import
    assert function_body_lines(source) == {5, 7, 8, 12}


@pytest.mark.parametrize("decorator", ["@cache", "@functools.lru_cache(maxsize=8)", "@cached_property"])
def test_a_module_that_memoises_has_no_line_judged_by_its_first_callers_alone(decorator):
    """rvtol.units's ``_pint`` is ``@cache``d: its line 197 was recorded only in the first test that read a unit by
    pint, that test passed on a mutant which every later unit test depends on, and the mutant was called a survivor
    (it fails tests/units/test_units_open.py). In such a module every mutant is judged by all the module's test
    files."""
    from mutation import function_body_lines

    plain = "def f(a):\n    return a + 1\ndef g(b):\n    return f(b) * 2\n"
    assert function_body_lines(plain) == {2, 4}
    assert function_body_lines(decorator + "\n" + plain) == set()


def _answering(tmp_path, answer: bytes | None):
    """A stand-in test server on ``tmp_path/server.sock`` that answers one client with ``answer`` (None: no server)."""
    import socket
    import threading

    if answer is None:
        return None
    srv = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    srv.bind(str(tmp_path / "server.sock"))
    srv.listen(1)

    def one():
        conn, _ = srv.accept()
        with conn:
            conn.recv(16)
            conn.sendall(answer)
        srv.close()

    t = threading.Thread(target=one, daemon=True)
    t.start()
    return t


@pytest.mark.parametrize("answer, code, output", [
    (b"0", 0, ""),                                         # the tests pass on the mutant: a survivor
    (b"1", 1, "killed: pytest exit 1"),                    # a test failed
    (b"2", 1, "killed: pytest exit 2"),                    # collecting the tests failed (the mutant breaks an import)
    (b"timeout", 1, "timeout"),
    (b"3", 1, "error: pytest exit 3"),                     # pytest's own internal error: not the tests' verdict
    (b"139", 1, "error: pytest exit 139"),                 # the test process crashed (a signal)
    (None, 1, "error: no answer from the test server"),    # the server had stopped: never 'killed'
])
def test_the_client_says_how_a_mutant_ended_and_only_a_failing_test_kills_it(tmp_path, capsys, answer, code,
                                                                               output):
    from mutation import client

    t = _answering(tmp_path, answer)
    assert client(tmp_path) == code
    assert capsys.readouterr().out.startswith(output)
    if t is not None:
        t.join(5)


def test_only_a_said_kill_or_a_timeout_counts_as_detected(tmp_path):
    """A result cosmic-ray recorded as KILLED counts as killed only when the client said a test failed; one recorded
    without saying how (before the client said it) is run again, an error is neither kill nor survivor."""
    import sqlite3

    from mutation import Module

    db_path = tmp_path / "session.sqlite"
    with sqlite3.connect(db_path) as db:
        db.execute("CREATE TABLE work_results (worker_outcome VARCHAR(9), output TEXT, test_outcome VARCHAR(11), "
                   "diff TEXT, job_id VARCHAR NOT NULL PRIMARY KEY)")
        db.executemany("INSERT INTO work_results VALUES ('NORMAL', ?, ?, '', ?)", [
            ("killed: pytest exit 1", "KILLED", "a"), ("timeout", "KILLED", "b"), ("", "KILLED", "c"),
            ("error: no answer from the test server", "KILLED", "d"), ("", "SURVIVED", "e")])
    m = Module.__new__(Module)
    m.session = db_path
    assert m.forget_unverified() == 2
    with sqlite3.connect(db_path) as db:
        assert sorted(r[0] for r in db.execute("SELECT job_id FROM work_results")) == ["a", "b", "e"]
