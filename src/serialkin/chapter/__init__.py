"""The chapter's worked examples, reproduced into an HTML report (``serialkin chapter``)."""
