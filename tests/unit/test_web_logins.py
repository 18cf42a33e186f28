"""The browser door's logins: random ids kept on the server, forgotten when they expire; the
trusted header believed from the proxy's addresses only."""

from __future__ import annotations

from workbench.door.networks import parse_networks
from workbench.web.cookies import MAX_LOGINS, Logins, digest, same_token
from workbench.web.proxy import header_login, origin_of


def test_a_login_names_its_user_until_it_expires_and_a_forged_id_names_nobody():
    now = [1000.0]
    logins = Logins(lifetime=60, clock=lambda: now[0])
    login_id, login = logins.open("ann", "student", "password")
    assert len(login_id) >= 40 and logins.get(login_id) is login
    assert logins.get(login_id[:-1] + ("A" if login_id[-1] != "A" else "B")) is None
    assert logins.get("x" * 10_000) is None and logins.get(None) is None
    now[0] += 59
    assert logins.get(login_id) is login
    now[0] += 1
    assert logins.get(login_id) is None and len(logins) == 0


def test_two_logins_have_different_ids_and_form_tokens():
    logins = Logins(lifetime=60)
    first_id, first = logins.open("ann", "student", "password")
    second_id, second = logins.open("ann", "student", "password")
    assert first_id != second_id and first.csrf != second.csrf
    logins.close_user("ann")
    assert logins.get(first_id) is None and logins.get(second_id) is None


def test_the_logins_kept_are_bounded():
    logins = Logins(lifetime=60)
    oldest, _ = logins.open("u0", "student", "password")
    for i in range(MAX_LOGINS):
        logins.open(f"u{i + 1}", "student", "password")
    assert len(logins) == MAX_LOGINS and logins.get(oldest) is None


def test_a_form_token_matches_only_itself():
    assert same_token("abc", "abc")
    assert not same_token("abd", "abc") and not same_token("", "") and not same_token(None, "x")


def test_the_user_header_and_forwarded_address_are_believed_from_the_proxy_only():
    proxy = parse_networks("10.0.0.5")
    headers = {"X-Forwarded-User": "ann", "X-Forwarded-For": "1.2.3.4, 192.0.2.7"}
    assert header_login("X-Forwarded-User", "10.0.0.5", headers, proxy).user == "ann"
    refused = header_login("X-Forwarded-User", "10.0.0.6", headers, proxy)
    assert refused.user == "" and "not a trusted proxy" in refused.refused
    assert origin_of("10.0.0.5", headers, proxy, tls=False).address == "192.0.2.7"
    assert origin_of("10.0.0.6", headers, proxy, tls=False).address == "10.0.0.6"
    secure = origin_of("10.0.0.5", {"X-Forwarded-Proto": "https"}, proxy, tls=False)
    assert secure.secure and not origin_of("10.0.0.6", {"X-Forwarded-Proto": "https"}, proxy,
                                           tls=False).secure  # fmt: skip


def test_logins_kept_in_a_folder_outlive_the_server_as_digests_until_they_expire(tmp_path):
    now = [1000.0]
    folder = tmp_path / "web-logins"
    before = Logins(lifetime=60, clock=lambda: now[0], folder=folder)
    login_id, login = before.open("ann", "student", "password")
    gone_id, _ = before.open("bob", "student", "password")
    before.close(gone_id)  # logged out: nothing kept
    (kept,) = folder.iterdir()
    assert kept.name == digest(login_id) and login_id not in kept.read_text()
    assert (kept.stat().st_mode & 0o777) == 0o600
    # a restart: a new server's logins from the same folder
    after = Logins(lifetime=60, clock=lambda: now[0], folder=folder)
    again = after.get(login_id)
    assert again is not None and (again.user, again.role, again.csrf) == (
        "ann", "student", login.csrf,
    )  # fmt: skip
    assert after.get(gone_id) is None and after.get("A" * 43) is None
    now[0] += 60
    assert after.get(login_id) is None and list(folder.iterdir()) == []


def test_an_expired_login_in_the_folder_is_removed_as_the_server_starts(tmp_path):
    now = [1000.0]
    folder = tmp_path / "web-logins"
    login_id, _ = Logins(lifetime=60, clock=lambda: now[0], folder=folder).open(
        "ann", "student", "password"
    )
    (folder / ("0" * 64)).write_text("not a login")
    now[0] += 61
    later = Logins(lifetime=60, clock=lambda: now[0], folder=folder)
    assert len(later) == 0 and later.get(login_id) is None and list(folder.iterdir()) == []
