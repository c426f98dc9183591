"""The editing loop: what an editor asks of a .bgr file (:mod:`.analysis`) and the language
server that answers it over LSP (:mod:`.lsp`, ``bgr lsp``)."""
