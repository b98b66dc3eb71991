"""A short, fixed-seed run of the case-file fuzzer (pipeline/fuzz_case.py; `make fuzz` runs it for
FUZZ_SECONDS): every mutated case file loads or is refused with a CaseError, none ends in another
exception or takes more than 5 s."""
from pipeline.fuzz_case import fuzz, mutate, seeds


def test_mutated_case_files_load_or_fail_cleanly():
    result = fuzz(seconds=60, seed=17, max_runs=400)
    assert result["runs"] == 400
    # The mutations reach both sides of the contract: some files still load, most are refused.
    assert 0 < result["loaded"] < result["runs"]
    assert not result["findings"], result["findings"][0][1]


def test_the_mutations_are_reproducible_from_the_seed():
    import random
    corpus = seeds()
    assert len(corpus) >= 9
    first = [mutate(corpus[0], corpus, random.Random(5)) for _ in range(3)]
    again = [mutate(corpus[0], corpus, random.Random(5)) for _ in range(3)]
    assert first == again and any(m != corpus[0] for m in first)
