"""Stop signals: the first asks for a stop at the next boundary, the second stops at once."""

from __future__ import annotations

import os
import signal

import pytest

from mtpg.evolve.stopping import STOP_SIGNALS, GracefulStop, StopNow, exit_code


def test_exit_codes_follow_the_128_plus_signal_convention() -> None:
    assert exit_code(signal.SIGINT) == 130
    assert exit_code(signal.SIGTERM) == 143
    assert exit_code(signal.SIGHUP) == 129
    assert set(STOP_SIGNALS) == {signal.SIGTERM, signal.SIGINT, signal.SIGHUP}


def test_stop_now_names_the_signal() -> None:
    stop = StopNow(signal.SIGTERM)
    assert isinstance(stop, KeyboardInterrupt)
    assert stop.signum == signal.SIGTERM and str(stop) == "SIGTERM"


def test_first_signal_sets_the_flag_and_says_so_second_stops_at_once(capfd) -> None:
    before = {sig: signal.getsignal(sig) for sig in STOP_SIGNALS}
    with GracefulStop("mtpg train", "generation 3") as stop:
        assert not stop.requested() and stop.name == "" and stop.signum is None
        for sig in STOP_SIGNALS:
            assert signal.getsignal(sig) == stop._handle
        try:
            os.kill(os.getpid(), signal.SIGTERM)
        except StopNow:  # a KeyboardInterrupt: would end the test run instead of failing
            pytest.fail("the first signal stopped at once")
        assert stop.requested() and stop.name == "SIGTERM" and stop.signum == signal.SIGTERM
        err = capfd.readouterr().err
        assert err == (
            "\nmtpg train: SIGTERM received; stopping after generation 3 "
            "(send it again to stop at once)\n"
        )
        with pytest.raises(StopNow) as raised:
            os.kill(os.getpid(), signal.SIGINT)
        assert raised.value.signum == signal.SIGINT
        assert stop.signum == signal.SIGTERM  # the first signal is the one recorded
    assert {sig: signal.getsignal(sig) for sig in STOP_SIGNALS} == before
    assert stop._old == {}


def test_default_label_and_message(capfd) -> None:
    with GracefulStop() as stop:
        os.kill(os.getpid(), signal.SIGHUP)
    assert stop.name == "SIGHUP"
    assert capfd.readouterr().err == (
        "\nmtpg: SIGHUP received; stopping after the generation under way "
        "(send it again to stop at once)\n"
    )


def test_handlers_outside_the_main_thread_are_skipped() -> None:
    import threading

    seen = {}

    def body() -> None:
        with GracefulStop() as stop:
            seen["old"] = dict(stop._old)

    thread = threading.Thread(target=body)
    thread.start()
    thread.join()
    assert seen["old"] == {}
