"""Random physical decks: small models (1 to 6 masses, springs in a chain, a star or at random,
1 to 6 friction devices of either law, five kinds of damping) under a harmonic, a recorded
(band-limited noise with an envelope) or no table motion, with random initial conditions and
integration settings. The same seed gives the same case on every machine.

Used by the campaigns that measure the run's own reports against the converged answer
(tests/fuzz/step_campaign.py; earlier, the implicit-against-step differential fuzz):

    c = gen_case(seed)
    deck = deck_text(c, 'step', n1=c['integ']['n1'])   # refinement 'step' or 'implicit'
    record = record_text(c)                            # for c['exc']['type'] == 'record': rec.txt
"""
import math
import random

G = 9.81


def fmt(x):
    return repr(float(x))


def gen_case(seed):
    r = random.Random(seed)
    c = {}
    n = r.randint(1, 6)
    mass = [10 ** r.uniform(-0.5, 1.5) for _ in range(n)]
    topo = r.choice(['chain', 'chain', 'chain+extra', 'random', 'star'])
    springs = []
    def kfor(m):
        T = 10 ** r.uniform(-1.3, 0.3)
        return m * (2 * math.pi / T) ** 2
    if topo.startswith('chain'):
        for i in range(1, n + 1):
            springs.append((i, i - 1, kfor(mass[i - 1])))
        if topo == 'chain+extra':
            for _ in range(r.randint(1, 3)):
                i = r.randint(1, n)
                j = r.randint(0, n)
                if i != j:
                    springs.append((i, j, kfor(mass[i - 1])))
    elif topo == 'star':
        for i in range(1, n + 1):
            springs.append((i, 0 if i == 1 else 1, kfor(mass[i - 1])))
    else:
        for i in range(1, n + 1):
            j = r.randint(0, n)
            while j == i:
                j = r.randint(0, n)
            springs.append((i, j, kfor(mass[i - 1])))
        if r.random() < 0.7:
            springs.append((r.randint(1, n), 0, kfor(mass[0])))
    # devices
    nd = r.randint(1, 4)
    lawmode = r.choice(['hysteretic', 'velocity', 'mixed', 'mixed'])
    devs = []
    for d in range(nd):
        i = r.randint(1, n)
        j = r.choice([0, 0] + list(range(0, n + 1)))
        while j == i:
            j = r.randint(0, n)
        law = lawmode if lawmode != 'mixed' else r.choice(['hysteretic', 'velocity'])
        mi = mass[i - 1]
        p = mi * G * 10 ** r.uniform(-1.3, 0.5)
        mu = r.uniform(0.02, 0.5)
        if r.random() < 0.03:
            mu = 0.0
        dev = dict(i=i, j=j, law=law, p=p, mu=mu)
        if r.random() < 0.7:
            dev['eps'] = 10 ** r.uniform(-5, -1.5)
        if r.random() < 0.7:
            dev['eps1'] = 10 ** r.uniform(-5, -1.5)
        if r.random() < 0.7:
            dev['f'] = 10 ** r.uniform(-7, -2)
        if law == 'velocity' and r.random() < 0.35:
            kind = r.choice(['exponential', 'table'])
            dev['mu_law'] = kind
            if kind == 'exponential':
                dev['mu_max'] = mu
                dev['mu_min'] = mu * r.uniform(0.3, 1.5)
                dev['mu_rate'] = 10 ** r.uniform(0, 2.5)
            else:
                k = r.randint(2, 5)
                v = sorted(set(round(r.uniform(0, 0.5), 4) for _ in range(k)))
                if len(v) < 2:
                    v = [0.0, 0.1]
                dev['tv'] = v
                dev['tmu'] = [r.uniform(0.03, 0.5) for _ in v]
        devs.append(dev)
    if r.random() < 0.15 and len(devs) < 6:
        dd = dict(devs[0]); dd['law'] = r.choice(['hysteretic', 'velocity']); dd.pop('mu_law', None)
        devs.append(dd)
    # damping
    damp = r.choice(['none', 'stiffness', 'rayleigh', 'rayleigh_modes', 'stiffness_T'])
    # excitation
    exc = {}
    if r.random() < 0.65:
        exc['type'] = 'harmonic'
        exc['freq'] = 10 ** r.uniform(-0.3, 1.0)
        pga = 10 ** r.uniform(-0.3, 1.3)
        exc['amp'] = pga / (2 * math.pi * exc['freq']) ** 2
        exc['dt_record'] = r.choice([0.002, 0.005, 0.01, 0.02])
        exc['duration'] = r.uniform(0.5, 5.0)
        if r.random() < 0.3:
            exc['ramp'] = r.randint(1, 3)
    elif r.random() < 0.85:
        exc['type'] = 'record'
        dtr = r.choice([0.005, 0.01, 0.02])
        exc['dt_record'] = dtr
        npts = int(r.uniform(0.8, 3.0) / dtr)
        pga = 10 ** r.uniform(-0.3, 1.0)
        # band-limited noise: sum of sinusoids with envelope
        comps = [(r.uniform(0.5, 10.0), r.uniform(0, 2 * math.pi), r.uniform(0.2, 1)) for _ in range(8)]
        vals = []
        for k in range(npts):
            t = k * dtr
            env = min(1.0, t / 0.3) * (1.0 if t < 0.6 * npts * dtr else math.exp(-(t - 0.6 * npts * dtr) * 3))
            vals.append(env * sum(a * math.sin(2 * math.pi * f * t + ph) for f, ph, a in comps))
        mx = max(abs(v) for v in vals) or 1.0
        exc['values'] = [v * pga / mx for v in vals]
        if r.random() < 0.3:
            exc['duration'] = npts * dtr * r.uniform(1.0, 1.5)
    else:
        exc['type'] = 'none'
        exc['dt_record'] = r.choice([0.005, 0.01])
        exc['duration'] = r.uniform(0.5, 2.0)
    ic = {}
    if exc['type'] == 'none' or r.random() < 0.4:
        ic['u0'] = [r.uniform(-0.02, 0.02) for _ in range(n)]
        if r.random() < 0.6:
            ic['v0'] = [r.uniform(-1.0, 1.0) * r.choice([1e-3, 0.1, 1]) for _ in range(n)]
    integ = dict(n1=r.randint(1, 40), n2=r.randint(1, 50), n=r.choice([1.01, 1.5, 2, 5, 10, 10, 20, 100]),
                 check=r.random() < 0.7)
    if r.random() < 0.1:
        integ['dt_min'] = 'half'
    if r.random() < 0.08:
        integ['beta'], integ['gamma'] = r.choice([(1 / 6, 0.5), (0.3025, 0.6), (0.25, 0.6)])
    if r.random() < 0.15:
        integ['linear_system'] = r.choice(['dense', 'banded'])
    return dict(n=n, mass=mass, springs=springs, devs=devs, damp=damp, exc=exc, ic=ic, integ=integ,
                seed=seed, topo=topo, lawmode=lawmode)


def deck_text(c, refinement, n1=None, name='run', record_name='rec.txt', xi_seed=None):
    r = random.Random(c['seed'] * 7 + 1)
    L = []
    n = c['n']
    L.append('&model')
    L.append(f"  n_dof = {n}")
    L.append('  mass = ' + ', '.join(fmt(m) for m in c['mass']))
    if 'u0' in c['ic']:
        L.append('  u0 = ' + ', '.join(fmt(x) for x in c['ic']['u0']))
    if 'v0' in c['ic']:
        L.append('  v0 = ' + ', '.join(fmt(x) for x in c['ic']['v0']))
    L.append('/')
    L.append('&springs')
    L.append(f"  n_springs = {len(c['springs'])}")
    L.append('  node_i = ' + ', '.join(str(s[0]) for s in c['springs']))
    L.append('  node_j = ' + ', '.join(str(s[1]) for s in c['springs']))
    L.append('  k = ' + ', '.join(fmt(s[2]) for s in c['springs']))
    L.append('/')
    L.append('&damping')
    d = c['damp']
    if d == 'none':
        L.append("  damping_type = 'none'")
    elif d == 'stiffness':
        L.append("  damping_type = 'stiffness'")
        L.append(f"  xi = {fmt(r.uniform(0, 0.1))}")
    elif d == 'stiffness_T':
        L.append("  damping_type = 'stiffness'")
        L.append(f"  xi = {fmt(r.uniform(0, 0.1))}")
        L.append(f"  period = {fmt(r.uniform(0.05, 1.0))}")
    elif d == 'rayleigh':
        L.append("  damping_type = 'rayleigh'")
        L.append(f"  rayleigh_a0 = {fmt(r.uniform(0, 1.0))}")
        L.append(f"  rayleigh_a1 = {fmt(r.uniform(0, 0.003))}")
    else:
        L.append("  damping_type = 'rayleigh'")
        L.append(f"  xi = {fmt(r.uniform(0.005, 0.08))}")
        L.append("  mode_i = 1")
        L.append(f"  mode_j = {min(2, n)}")
        if n == 1:
            L[-1] = "  mode_j = 1"
    L.append('/')
    devs = c['devs']
    L.append('&friction')
    L.append(f"  n_devices = {len(devs)}")
    L.append('  node_i = ' + ', '.join(str(x['i']) for x in devs))
    L.append('  node_j = ' + ', '.join(str(x['j']) for x in devs))
    L.append('  law = ' + ', '.join(f"'{x['law']}'" for x in devs))
    L.append('  p = ' + ', '.join(fmt(x['p']) for x in devs))
    if not any('mu_law' in x for x in devs):
        L.append('  mu = ' + ', '.join(fmt(x['mu']) for x in devs))
    else:
        for k, x in enumerate(devs, 1):
            if 'mu_law' not in x:
                L.append(f"  mu({k}) = {fmt(x['mu'])}")
    for key in ('eps', 'eps1', 'f'):
        for k, x in enumerate(devs, 1):
            if key in x:
                L.append(f"  {key}({k}) = {fmt(x[key])}")
    for k, x in enumerate(devs, 1):
        if 'mu_law' in x:
            L.append(f"  mu_law({k}) = '{x['mu_law']}'")
            if x['mu_law'] == 'exponential':
                L.append(f"  mu_max({k}) = {fmt(x['mu_max'])}, mu_min({k}) = {fmt(x['mu_min'])}, "
                         f"mu_rate({k}) = {fmt(x['mu_rate'])}")
            else:
                L.append(f"  mu_table_v(:, {k}) = " + ', '.join(fmt(v) for v in x['tv']))
                L.append(f"  mu_table_mu(:, {k}) = " + ', '.join(fmt(v) for v in x['tmu']))
    L.append('/')
    e = c['exc']
    L.append('&excitation')
    L.append(f"  excitation_type = '{e['type']}'")
    L.append(f"  dt_record = {fmt(e['dt_record'])}")
    if e['type'] == 'harmonic':
        L.append(f"  amplitude = {fmt(e['amp'])}")
        L.append(f"  frequency = {fmt(e['freq'])}")
        L.append(f"  duration = {fmt(e['duration'])}")
        if 'ramp' in e:
            L.append(f"  ramp_cycles = {e['ramp']}")
    elif e['type'] == 'record':
        L.append(f"  record_file = '{record_name}'")
        L.append("  record_format = 'values'")
        if 'duration' in e:
            L.append(f"  duration = {fmt(e['duration'])}")
    else:
        L.append(f"  duration = {fmt(e['duration'])}")
    L.append('/')
    it = c['integ']
    L.append('&integration')
    L.append(f"  n1 = {n1 if n1 is not None else it['n1']}")
    L.append(f"  n2 = {it['n2']}")
    L.append(f"  n = {fmt(it['n'])}")
    L.append(f"  check_correctness = {'.true.' if it['check'] else '.false.'}")
    if 'beta' in it:
        L.append(f"  beta = {fmt(it['beta'])}, gamma = {fmt(it['gamma'])}")
    if it.get('dt_min') == 'half':
        nn1 = n1 if n1 is not None else it['n1']
        L.append(f"  dt_min = {fmt(e['dt_record'] / nn1 / it['n2'] / 2)}")
    if 'linear_system' in it:
        L.append(f"  linear_system = '{it['linear_system']}'")
    L.append(f"  refinement = '{refinement}'")
    L.append('/')
    L.append('&output')
    L.append("  dir = 'out'")
    L.append(f"  name = '{name}'")
    L.append("  output_every = 1")
    L.append("  n_modes = 2")
    L.append('/')
    return '\n'.join(L) + '\n'


def record_text(c):
    return ''.join(f"{v:.12e}\n" for v in c['exc']['values'])
