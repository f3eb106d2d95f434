"""The advise room of the report.

Which engine for a scene: the envelope of a scene, the judged and graded answers
(`crosscheck advise`) and the page's form.
"""
