"""`lmcr serve`: a local web page to try the robot. A person puts objects on the table, types or records
an instruction, and sees its frame, the completion with its probabilities, the robot's question and an
answer box when it is unsure, and the simulated execution as an animation.

`app.create_app` builds the FastAPI application from explicit inputs (a workspace, the scorer);
`app.serve` runs it with uvicorn; `robot` holds what each request asks of the models; `static/` is the
page (plain HTML, CSS and JavaScript, no build step).
"""
