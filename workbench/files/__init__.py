"""Reading and writing files safely: bounded reads of untrusted text, and the workspace a
served student is confined to."""
