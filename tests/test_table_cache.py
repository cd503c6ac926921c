"""The cache on disk of computed tables (``warpcaustics/io/table_cache.py``): a table read back is the
one computed, bit for bit; a changed input or formula is another file; a damaged file is computed
again; a folder that cannot be written, or the cache turned off, only means no cache."""

from pathlib import Path

import numpy as np
import pytest

from warpcaustics.io.table_cache import CACHE_ENV, cache_folder, cached_table, table_key


def _counting(table: np.ndarray):
    calls = []

    def compute():
        calls.append(1)
        return table.copy()

    return compute, calls


def test_a_table_is_computed_once_and_read_back_bit_for_bit(tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    table = np.random.default_rng(1).random(17)
    compute, calls = _counting(table)
    key = table_key(table, "inputs")
    first = cached_table("t", key, compute, table.shape)
    again = cached_table("t", key, compute, table.shape)
    assert len(calls) == 1 and np.array_equal(first, table) and np.array_equal(again, table)
    assert [p.name for p in (tmp_path / "cache").iterdir()] == [f"t-{key[:32]}.npy"]  # no temporary left


def test_the_key_follows_every_input_and_the_formula():
    a = np.arange(4.0)

    def f(x):
        return x + 1

    def g(x):
        return x + 2

    keys = {table_key(a, f), table_key(a + 1e-12, f), table_key(a.astype(np.float32), f), table_key(a, g),
            table_key(a, f, 2000), table_key(a.reshape(2, 2), f)}
    assert len(keys) == 6 and table_key(a, f) == table_key(a.copy(), f)
    assert table_key(a, len) is None  # a built-in's source cannot be read: no key, no cache


@pytest.mark.parametrize("damage", [b"not a numpy file", "wrong shape", "not finite"])
def test_a_damaged_table_is_computed_again_and_replaced(tmp_path, monkeypatch, damage):
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    table = np.linspace(0.0, 1.0, 5)
    key = table_key(table)
    path = tmp_path / f"t-{key[:32]}.npy"
    if isinstance(damage, bytes):
        path.write_bytes(damage)
    else:
        np.save(path, np.ones(3) if damage == "wrong shape" else np.full(5, np.nan))
    compute, calls = _counting(table)
    assert np.array_equal(cached_table("t", key, compute, table.shape), table) and len(calls) == 1
    assert np.array_equal(np.load(path), table)


def test_no_folder_to_write_or_the_cache_off_still_gives_the_table(tmp_path, monkeypatch):
    (tmp_path / "a_file").write_text("")
    table = np.arange(3.0)
    for setting in (str(tmp_path / "a_file" / "cache"), "off"):
        monkeypatch.setenv(CACHE_ENV, setting)
        compute, calls = _counting(table)
        for _ in range(2):
            assert np.array_equal(cached_table("t", table_key(table), compute, table.shape), table)
        assert len(calls) == 2
    assert cache_folder() is None
    monkeypatch.setenv(CACHE_ENV, "~/tables")  # as a shell would not expand it inside quotes
    assert cache_folder() == Path.home() / "tables"
    monkeypatch.delenv(CACHE_ENV)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_folder() == tmp_path / "xdg" / "warpcaustics"


def test_the_small_angle_spread_table_from_the_cache_is_the_computed_one(tmp_path, monkeypatch):
    """G(x) of Petzold's HAOCE 11 (the default station) read back from the cache is the table the
    Hankel transform gives with the cache off, bit for bit."""
    from warpcaustics.config import PhaseFunctionKind
    from warpcaustics.optics.phase import phase_quadrature
    from warpcaustics.optics.small_angle import spread_from_phase

    quadrature = phase_quadrature(PhaseFunctionKind.PETZOLD, None, "HAOCE 11")
    monkeypatch.setenv(CACHE_ENV, "off")
    x, direct = spread_from_phase(*quadrature)
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    spread_from_phase(*quadrature)  # computed and written
    assert len(list(tmp_path.glob("spread-*.npy"))) == 1
    x_again, cached = spread_from_phase(*quadrature)
    assert np.array_equal(x_again, x) and np.array_equal(cached, direct)
