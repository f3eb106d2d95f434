"""Layer 3, what is right and how right an answer is: the oracle bridge, scene truth, scoring."""
