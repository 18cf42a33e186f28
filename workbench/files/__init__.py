"""Reading and writing files safely: bounded reads of untrusted text, the one way a file is
written whole, and the workspace a served student is confined to."""
