"""The live keyboard of `viple run --connect`: a raw terminal's bytes as VIPLE's key names, and
a terminal that always comes back as it was."""

from __future__ import annotations

import os
import termios

import pytest

from workbench.cli.keyboard import QUIT, KeyDecoder, raw_terminal


def test_letters_digits_and_space_are_their_keys():
    decoder = KeyDecoder()
    assert decoder.feed(b"wW7 a") == ["w", "w", "7", "space", "a"]
    assert not decoder.waiting


def test_keys_viple_has_no_number_for_are_left_out():
    assert KeyDecoder().feed(b"\r\t+-.\x7f\x04\xc3\xa9") == []


def test_arrows_in_both_terminal_modes_and_split_across_reads():
    decoder = KeyDecoder()
    assert decoder.feed(b"\x1b[A\x1b[B\x1bOC\x1bOD") == ["up", "down", "right", "left"]
    assert decoder.feed(b"w\x1b[") == ["w"] and decoder.waiting
    assert decoder.feed(b"A") == ["up"] and not decoder.waiting
    assert decoder.feed(b"\x1b[1;5C") == ["right"]  # ctrl+right: still the right arrow


def test_other_sequences_and_alt_keys_are_not_keys():
    decoder = KeyDecoder()
    assert decoder.feed(b"\x1b[5~\x1bOP\x1b[15~") == []  # page up, F1, F5
    assert decoder.feed(b"\x1bw") == []  # alt+w
    assert decoder.feed(b"\x1b[" + b"1;" * 20 + b"Aa") == ["a"]  # too long: dropped, then a


def test_ctrl_c_quits_at_once_and_a_lone_esc_after_the_wait():
    decoder = KeyDecoder()
    assert decoder.feed(b"w\x03") == ["w", QUIT]
    assert decoder.feed(b"\x1b") == [] and decoder.waiting
    assert decoder.flush() == [QUIT]
    assert decoder.feed(b"\x1b\x1b[A") == [QUIT, "up"]  # Esc, then an arrow
    assert decoder.feed(b"\x1b[") == []
    assert decoder.flush() == []  # an unfinished sequence is not Esc


def test_raw_mode_is_undone_even_when_the_block_fails():
    master, slave = os.openpty()
    try:
        before = termios.tcgetattr(slave)
        with pytest.raises(RuntimeError), raw_terminal(slave):
            raw = termios.tcgetattr(slave)
            assert not raw[3] & termios.ECHO and not raw[3] & termios.ISIG
            raise RuntimeError("the run failed")
        assert termios.tcgetattr(slave) == before
        with raw_terminal(slave):
            pass
        assert termios.tcgetattr(slave) == before
    finally:
        os.close(master)
        os.close(slave)
