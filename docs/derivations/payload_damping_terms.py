"""Check of Eqs. P2-P5 (docs/amm.md 11.1) and of the rate Hessians of Eq. D8 (docs/fem.md 9.2)
on independent numerics (not flexstar's code).

P2-P5: the payload's exact generalized inertia force on z = (u, w, psi), from finite differences
of the exact centre-of-mass position along arbitrary rigid and elastic motions, against
M_p z'' + D_p z' + K_p z - f_p: the difference must vanish at zero elastic amplitude (up to the
finite-difference error) and grow like the amplitude squared (the linearisation is exact to
first order).

D8: d p'/dq of the co-rotational element (p = (u, th1, th2), p' = B q') against central
differences.

Run: python3 docs/derivations/payload_damping_terms.py (numpy).
"""
import numpy as np

m,J,ox,oy=2.3,0.07,0.05,-0.03
th=lambda t: 0.3*np.sin(1.3*t)+0.2*t*t
G=lambda t: np.array([0.1*np.cos(2*t), 0.05*t**3])
def z(t,eps): return eps*np.array([np.sin(3*t+0.2), np.cos(2.5*t), np.sin(1.7*t+1)])
def rot(a): return np.array([[np.cos(a),-np.sin(a)],[np.sin(a),np.cos(a)]])
def frame(t):
    a=th(t); ex=np.array([np.sin(a),-np.cos(a)]); ew=np.array([np.cos(a),np.sin(a)]); return ex,ew
def rc(t,eps):
    ex,ew=frame(t); u,w,psi=z(t,eps)
    o=ox*ex+oy*ew
    return G(t)+u*ex+w*ew+rot(psi)@o
def d(f,t,k=1,h=1e-3):
    if k==1: return (f(t+h)-f(t-h))/(2*h)
    return (f(t+h)-2*f(t)+f(t-h))/h**2
def exact(t,eps):
    a=d(lambda s: rc(s,eps),t,2)
    ex,ew=frame(t); u,w,psi=z(t,eps)
    rho=rot(psi)@(ox*ex+oy*ew); kx=np.array([-rho[1],rho[0]])
    ang2=d(lambda s: th(s)+z(s,eps)[2],t,2)
    return np.array([m*a@ex, m*a@ew, m*a@kx+J*ang2])
def linear(t,eps):
    ex,ew=frame(t); aG=d(G,t,2); a1,a2=aG@ex,aG@ew
    t1=d(th,t); t2=d(th,t,2)
    zz=z(t,eps); z1=d(lambda s: z(s,eps),t); z2=d(lambda s: z(s,eps),t,2)
    Mp=np.array([[m,0,-m*oy],[0,m,m*ox],[-m*oy,m*ox,J+m*(ox*ox+oy*oy)]])
    Dp=2*m*t1*np.array([[0,-1,-ox],[1,0,-oy],[ox,oy,0]])
    Kp=m*np.array([[-t1**2,-t2,-t2*ox+t1**2*oy],[t2,-t1**2,-t2*oy-t1**2*ox],[t2*ox+t1**2*oy,t2*oy-t1**2*ox,-(ox*a1+oy*a2)]])
    fp=-np.array([m*(a1-t2*oy-t1**2*ox), m*(a2+t2*ox-t1**2*oy), m*(ox*a2-oy*a1)+(J+m*(ox*ox+oy*oy))*t2])
    return Mp@z2+Dp@z1+Kp@zz-fp
print("Eqs. P2-P5: t, amplitude, |exact - linear|, |exact|")
for t in (0.3,1.1):
    for eps in (0.0,1e-2,2e-2):
        e=exact(t,eps); l=linear(t,eps)
        print(t,eps,np.abs(e-l).max(), np.abs(e).max())

print("Eq. D8 rate Hessians: largest |difference|, largest entry")
rng=np.random.default_rng(1)
l0=0.01; b0=0.3
q=np.array([0,0,0.01, l0*np.cos(b0)+1e-4, l0*np.sin(b0)-2e-4, -0.02])+rng.normal(0,1e-5,6)
qd=rng.normal(0,1,6)
def p(q):
    d=q[3:5]-q[0:2]; ln=np.hypot(*d); b=np.arctan2(d[1],d[0])
    return np.array([ln-l0, q[2]-(b-b0), q[5]-(b-b0)])
def pdot(q,qd,h=1e-7): return (p(q+h*qd)-p(q-h*qd))/(2*h)
def formulas(q,qd):
    d=q[3:5]-q[0:2]; ln=np.hypot(*d); c,s=d/ln
    r=np.array([-c,-s,0,c,s,0]); z=np.array([s,-c,0,-s,c,0])
    bd=z@qd/ln; ud=r@qd
    du=bd*z; dth=(ud/ln**2)*z+(bd/ln)*r
    return np.array([du,dth,dth])
h=1e-6
num=np.array([(pdot(q+h*np.eye(6)[j],qd)-pdot(q-h*np.eye(6)[j],qd))/(2*h) for j in range(6)]).T
print(np.abs(num-formulas(q,qd)).max(), np.abs(formulas(q,qd)).max())
