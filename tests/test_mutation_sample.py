"""The mutation sample (tools/mutation_sample.py) stays applicable to the current code:
each mutation's original text is found exactly once in its module, and the tests it runs
exist. Running the sample itself takes minutes: `python tools/mutation_sample.py`."""

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))
import mutation_sample  # noqa: E402


def test_the_sample_has_at_least_twenty_mutations_over_every_layer():
    assert len(mutation_sample.MUTATIONS) >= 20
    layers = {mutation.file.split("/")[0] for mutation in mutation_sample.MUTATIONS}
    assert {"files", "markers", "models", "gait", "rigid_body"} <= layers


@pytest.mark.parametrize("mutation", mutation_sample.MUTATIONS,
                         ids=lambda mutation: f"{mutation.file}: {mutation.what}")
def test_each_mutation_applies_once_and_names_existing_tests(mutation):
    text = (ROOT / "bmc_functions" / mutation.file).read_text(encoding="utf-8")
    assert text.count(mutation.original) == 1
    assert mutation.original != mutation.mutant
    for test in mutation.tests:
        assert (ROOT / test.split("::")[0]).exists(), test
