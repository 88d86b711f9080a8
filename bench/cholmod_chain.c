/* One-off comparison for docs/theory.md section 10: CHOLMOD's update/downdate, solve and
 * factorization on the same kind of matrix as a shear building's K^ (tridiagonal, natural
 * order, simplicial LDL'), processor time per call. Needs Debian's libsuitesparse-dev, which
 * frictiondyn does not depend on: run by `bash bench/banded.sh cholmod`. */
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <time.h>
#include <suitesparse/cholmod.h>
static double cpu(void){ struct timespec t; clock_gettime(CLOCK_PROCESS_CPUTIME_ID,&t); return t.tv_sec+1e-9*t.tv_nsec; }
int main(void){
  int sizes[] = {10, 100, 1000, 10000};
  cholmod_common c; cholmod_start(&c);
  c.nmethods = 1; c.method[0].ordering = CHOLMOD_NATURAL; c.postorder = 0;
  c.supernodal = CHOLMOD_SIMPLICIAL; c.final_ll = 0;
  printf("%6s %12s %12s %12s\n","n","updown_us","solve_us","factor_us");
  for (int s=0;s<4;s++){
    int n=sizes[s];
    /* upper triangle of a tridiagonal SPD matrix, stype = 1 */
    cholmod_sparse *A = cholmod_allocate_sparse(n,n,2*n-1,1,1,1,CHOLMOD_REAL,&c);
    int *Ap=A->p,*Ai=A->i; double *Ax=A->x; int k=0;
    for(int j=0;j<n;j++){ Ap[j]=k; if(j>0){Ai[k]=j-1;Ax[k]=-2e8;k++;} Ai[k]=j;Ax[k]=4e9+4e8;k++; }
    Ap[n]=k;
    cholmod_factor *L = cholmod_analyze(A,&c); cholmod_factorize(A,L,&c);
    cholmod_dense *b = cholmod_ones(n,1,CHOLMOD_REAL,&c);
    /* update vector: sqrt(kd) (e_i - e_{i+1}) */
    cholmod_sparse *C = cholmod_allocate_sparse(n,1,2,1,1,0,CHOLMOD_REAL,&c);
    double t0,t; int reps;
    reps = n<=100?100000:(n<=1000?20000:2000);
    t0=cpu();
    for(int r=0;r<reps;r++){
      int i = (int)((r*7919L)%(n-1));
      int *Cp=C->p,*Ci=C->i; double *Cx=C->x;
      Cp[0]=0;Cp[1]=2;Ci[0]=i;Ci[1]=i+1;Cx[0]=sqrt(3e9);Cx[1]=-sqrt(3e9);
      cholmod_updown(1,C,L,&c);
      cholmod_updown(0,C,L,&c);
    }
    t=(cpu()-t0)/(2.0*reps);
    double ts, tf;
    t0=cpu(); for(int r=0;r<reps;r++){ cholmod_dense *x=cholmod_solve(CHOLMOD_A,L,b,&c); cholmod_free_dense(&x,&c);} ts=(cpu()-t0)/reps;
    int rf = reps/10;
    t0=cpu(); for(int r=0;r<rf;r++){ cholmod_factorize(A,L,&c);} tf=(cpu()-t0)/rf;
    printf("%6d %12.3f %12.3f %12.3f\n",n,1e6*t,1e6*ts,1e6*tf);
    cholmod_free_sparse(&C,&c); cholmod_free_dense(&b,&c); cholmod_free_factor(&L,&c); cholmod_free_sparse(&A,&c);
  }
  cholmod_finish(&c); return 0;
}
