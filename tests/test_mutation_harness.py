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
