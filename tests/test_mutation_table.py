"""The mutation check's table stays true to the code (benchmarks/mutation.py): each planted bug's old text occurs
exactly once in its file, so ``--list`` and ``--only`` run.  Code that moves (a GLSL function into another chunk, a
twin into another module) makes an entry stale; this says which, in the suite, instead of at the next mutation run."""
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _mutation_module():
    spec = importlib.util.spec_from_file_location("glphong_mutation_table", ROOT / "benchmarks" / "mutation.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_mutation_applies_exactly_once():
    mutation = _mutation_module()
    assert len(mutation.MUTATIONS) > 100
    assert mutation.problems(mutation.MUTATIONS, ROOT) == []


def test_a_stale_entry_is_named():
    mutation = _mutation_module()
    stale = mutation.Mutation("stale", "glsl/common.glsl", "text that is in no chunk", "other text", "a stale entry")
    (found,) = mutation.problems([stale], ROOT)
    assert "stale" in found and "occurs 0 times" in found


def test_a_run_stopped_after_a_failed_test_is_caught_not_a_collection_error():
    """pytest-xdist ends a ``-x`` run with exit 2 after the first failure: that is a caught mutation; exit 2 without a
    failed test is a collection error (still counted as caught, and said so)."""
    verdict = _mutation_module().verdict
    assert verdict(1) == "caught" and verdict(0) == "MISSED" and verdict(None) == "error (timeout)"
    assert verdict(2, "FAILED tests/test_x.py::test_y - AssertionError\n!!! xdist.dsession.Interrupted") == "caught"
    assert verdict(2, "ERROR tests/test_x.py - ImportError: no module\n!!! Interrupted") == "caught (collection error)"
