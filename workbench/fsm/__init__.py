"""The FSM language: a machine's definition and its checks (``definition.py``), its guard and
action expressions (``expr.py``), the engine that runs it (``machine.py``), its YAML files
(``yaml_file.py``), the built-in algorithms (``algorithms/``) and which files are shipped
(``bundled.py``), and what the FSM editor needs of it: the draft file (``editing.py``), the
forms' edits (``forms.py``) and the diagram's layout (``diagram.py``). It knows nothing of the
station; ``workbench.control`` runs machines on one."""
