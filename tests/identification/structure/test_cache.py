"""The identification's per-Description results live beside the Description, keyed by it, and
go with it: the Description has no mutable field, and two Descriptions never share an entry."""

import dataclasses
import gc

import numpy as np

from phantom_pin import describe
from phantom_pin.identification.structure import cache, constants


def test_the_description_is_immutable_and_carries_no_cache():
    description = describe("premium_1_5", overrides={"l1": 0.2096})
    assert "cache" not in {field.name for field in dataclasses.fields(description)}
    assert all(isinstance(getattr(description, f.name), (str, type(None), type(description.config),
                                                         type(description.model)))
               for f in dataclasses.fields(description))


def test_computed_once_per_description_and_dropped_with_it():
    calls = []
    first, second = describe("premium_1_5", overrides={"l1": 0.21}), describe("premium_1_5", overrides={"l1": 0.21})
    for description in (first, first, second):
        cache.cached(description, "probe", lambda: calls.append(1) or len(calls))
    assert calls == [1, 1]                      # once for first, once for second: not shared
    assert cache.cached(first, "probe", lambda: 99) == 1
    count = len(cache._ENTRIES)
    del first
    gc.collect()
    assert len(cache._ENTRIES) == count - 1     # its entries went with it


def test_a_cached_result_is_the_fresh_computation():
    """The report constants' matrix (C, with constants = C x) of a Description, cached, equals
    the same matrix of a second Description of the same configuration computed afresh, and
    C x0 is the closed form's constants of the configuration (linear in x, lengths fixed)."""
    a, b = describe("touch"), describe("touch")
    first = constants.constants_matrix(a)
    assert np.array_equal(constants.constants_matrix(a), first)
    assert np.array_equal(constants.constants_matrix(b), first)
