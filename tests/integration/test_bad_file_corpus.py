"""The command line on a corpus of bad files: every one is refused by name, quickly, with no
traceback. The slowest run and the largest process are printed (run with -s to see them).

Each command runs in a process of its own, forked from one that has imported the command line
(tests/cli_forker.py), so the seconds and the memory are those of refusing the file, without
the interpreter's start that is the same for every file (bench/bad_files.py times whole
processes started afresh)."""

from __future__ import annotations

import resource

import pytest

from tests.bad_files import SECRET, run_corpus

#: generous: a refusal takes well under a second on a quiet machine
MAX_SECONDS = 10.0
#: peak memory of one refusing process, far below what parsing a huge maze took
MAX_RSS_MIB = 200


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    return run_corpus(tmp_path_factory.mktemp("corpus"), jobs=2, forked=True)


def test_every_bad_file_is_refused_by_name_without_a_traceback(outcomes):
    for o in outcomes:
        where = f"{o.bad.filename}: workbench {' '.join(o.args)}"
        assert "Traceback" not in o.output, where
        assert o.code != 0, where
        assert o.bad.filename in o.output, where
        assert SECRET not in o.output, where
        assert len(o.output.splitlines()) < 40, where


def test_each_refusal_is_quick_and_small(outcomes):
    slowest = max(outcomes, key=lambda o: o.seconds)
    largest = max(outcomes, key=lambda o: o.max_rss_kib)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(
        f"\n{len(outcomes)} runs; slowest {slowest.seconds:.2f} s ({slowest.bad.filename}); "
        f"largest {largest.max_rss_kib / 1024:.1f} MiB ({largest.bad.filename}); "
        f"RUSAGE_CHILDREN max RSS {children.ru_maxrss / 1024:.1f} MiB"
    )
    assert slowest.seconds < MAX_SECONDS, slowest.bad.filename
    assert largest.max_rss_kib / 1024 < MAX_RSS_MIB, largest.bad.filename
