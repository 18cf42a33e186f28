"""What makes a served app cheap, and every use of Textual's private parts.

A lab server runs one app process per student, and a student driving sends some twenty keys a
second; the modules here cut what each key, tick and frame costs the server (measured with
``bench/tui_cpu.py``, see ``docs/ssh.md``):

  * ``terminal_driver``: Textual's web driver reading the session's input on the event loop
    (the packets it speaks with the server are the wire's, ``workbench/wire/packets.py``);
  * ``quick_keys`` and ``binding_chain``: a driving key runs its action without a key event,
    and a screen's binding chain is built only when it changed;
  * ``prompt_frames`` and ``compositor``: a change is drawn in the wake that made it, rendering
    only the widgets it shows;
  * ``single_layout``: a change of a widget's size lays the screen out once (Textual laid it out
    a second time, to the same result), and what the layout resized is drawn in its frame;
  * ``loop_clock``: the simulation's tick as one timer handle, ticking early when a key wakes
    the app anyway;
  * ``warmup``: the stylesheets parsed once in the fork server for every app forked after it.

``ordered_keys`` makes keys typed together act as they would one by one: a key is handed on
only once the key before it has gone its whole way, bindings and all.
``key_budget`` bounds what a flood of typed keys costs the app: past a burst and a rate the
keys are dropped and the student told how many.

These reach into Textual beyond its public interface, and so does ``tui/textual_private.py``
beside this package, the few private parts the rest of the TUI needs (each behind a name that
says what it gives). Nothing else touches Textual's private modules or attributes, and
``tests/unit/test_textual_internals.py`` checks that each part relied on here is still there,
with the shape relied on, in the Textual installed.
"""
