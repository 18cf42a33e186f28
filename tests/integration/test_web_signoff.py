"""An instructor signs off a student's exercise in their own browser page: the student asks
with the ready key on theirs, the request shows on the instructor's console, the passphrase is
typed only on the instructor's page, and the student's page shows the sign-off."""

from __future__ import annotations

from tests.app.support import sync
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.store.store import Store

from .ssh_support import Account, open_exercise
from .web_support import PASSWORD, web_host

PASSPHRASE = "correct horse battery"
FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only


@sync
async def test_the_instructor_signs_in_their_own_page_and_the_students_page_shows_it(tmp_path):
    accounts = [Account("ann", password=PASSWORD), Account("ito", "instructor", password=PASSWORD)]
    async with web_host(tmp_path, accounts) as host:
        create_instructor(host.data_dir, "ito", PASSPHRASE, kdf=FAST)
        ann = host.browser()
        await ann.login("ann")
        student = await ann.page()
        await student.start_app()
        await open_exercise(student, "Unity simulator: Drive by wire")
        assert "Sign off" not in await student.wait_for("r Ready")
        student.send("i")
        student.send("r")
        await student.wait_for("1st in the queue")

        ito = host.browser()
        await ito.login("ito")
        instructor = await ito.page()
        await instructor.wait_for("Sign-off queue: 1 waiting", "1. ann", timeout=90)
        instructor.send("\r")
        await instructor.wait_for("ann ask for sign-off", "objectives pass")
        instructor.send(PASSPHRASE)  # typed on the instructor's own page
        await instructor.wait_for("•" * len(PASSPHRASE))
        instructor.send("\t")
        instructor.send("checked at the console")
        await instructor.wait_for("at the console")
        instructor.send("\t")
        instructor.send(" ")
        await instructor.wait_for("[X] Override")
        instructor.send("\x13")  # ctrl+s signs
        await instructor.wait_for("signed off ann unity-simulator/drive-by-wire as ito")
        await student.wait_for("[*] Drive by wire", "signed off by ito on", timeout=10)
        for page in (student, instructor):
            await page.close()
        for browser in (ann, ito):
            await browser.close()

    with Store.open(host.data_dir, create=False) as store:
        (record,) = store.signoffs.of()
    assert (record.instructor, record.student, record.override) == ("ito", "ann", True)
