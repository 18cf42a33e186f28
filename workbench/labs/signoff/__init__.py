"""Signing off: the record, the instructors' keys and roster, signing, checking the log,
and the gradebook."""
