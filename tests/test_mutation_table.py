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
