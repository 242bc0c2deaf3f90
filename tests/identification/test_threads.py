"""``single_threaded``: one thread for BLAS and OpenMP, entered once."""

from threadpoolctl import threadpool_info

from hwpts.identification import threads
from hwpts.identification.threads import single_threaded


def _threads():
    return {info["filepath"]: info["num_threads"] for info in threadpool_info()}


def test_every_library_is_limited_inside_and_restored_after(monkeypatch):
    before = _threads()
    with single_threaded():
        inside = _threads()
        # scipy's own BLAS and scikit-learn's OpenMP are loaded first, so they are limited too
        assert any("gomp" in path for path in inside)
        assert all(n == 1 for n in inside.values())
        calls = []
        monkeypatch.setattr(threads, "threadpool_limits", lambda **kw: calls.append(kw))
        with single_threaded("openmp"):  # nested: nothing to do, no scan of the libraries
            assert all(n == 1 for n in _threads().values())
        assert calls == []
    after = _threads()
    assert all(after[path] == before.get(path, after[path]) for path in after)


def test_a_single_api_limit_does_not_mark_the_others_limited(monkeypatch):
    with single_threaded("openmp"):
        assert not threads._ALL_LIMITED.get()
    with single_threaded():
        assert threads._ALL_LIMITED.get()
    assert not threads._ALL_LIMITED.get()
