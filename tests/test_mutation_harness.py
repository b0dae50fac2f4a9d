"""The mutation harness's own rule (tests/mutation.py): the mutants it skips as annotations are those in
annotations a module never evaluates, and no others (spans counted by hand)."""
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
