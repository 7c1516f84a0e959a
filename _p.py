import time, numpy as np
import sim.vocal.produce as P
from sim.vocal.tract import VocalTract
t=VocalTract()
for ns, noise in [(8,0.2),(24,0.3),(24,0.5)]:
    P.START_NOISE=noise
    t0=time.time(); m,d=P.find_word_params('yeo',t,n_starts=ns,seed=5); print(ns,noise,d,time.time()-t0)
